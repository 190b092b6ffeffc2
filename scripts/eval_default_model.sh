#!/usr/bin/env bash
# Run the experiments of `betr eval` with the embedded models and copy the tables and
# charts into docs/ (docs/EVAL.md, "Results with the embedded models", and the failures
# and parameters in docs/EVAL-failures.md). The models are
# fetched into the cache on first use. Each command resumes from its directory if
# interrupted: run this script again.
# Usage: bash scripts/eval_default_model.sh [RUNS] [THREADS]
set -euo pipefail
cd "$(dirname "$0")/.."
runs="${1:-3}"
threads="${2:-2}"
out="eval-results/embedded"
mkdir -p "$out" docs/images
cargo build --release --locked
betr=target/release/betr
local=(--backend local --threads "$threads")

# Goals: the default model as the product reads instructions (examples retrieved per
# request, candidates checked, vote, feedback; the first call alone is scored too, which
# is the run without checks), then the fast model.
"$betr" eval goals "${local[@]}" --out "$out/goals-1.5b"
"$betr" eval goals "${local[@]}" --model qwen2.5-coder-0.5b --out "$out/goals-0.5b"

# Failures and values: the goal read from the instruction (a misread goal is its own
# column), and the scenario's stated goal (the failure is always reached).
"$betr" eval resolve "${local[@]}" --runs "$runs" --out "$out/resolve"
"$betr" eval params "${local[@]}" --runs "$runs" --out "$out/params"
"$betr" eval resolve "${local[@]}" --runs "$runs" --goal scenario --out "$out/resolve-scenario-goal"
"$betr" eval params "${local[@]}" --runs "$runs" --goal scenario --out "$out/params-scenario-goal"

# Latency, on an otherwise idle machine: both models, one and two threads.
for model in qwen2.5-coder-1.5b qwen2.5-coder-0.5b; do
  for t in 1 2; do
    "$betr" bench llm --model "$model" --threads "$t"
  done
done

cp "$out/goals-1.5b/accuracy.png" docs/images/eval-goals-default-model.png
cp "$out/resolve/resolve.png" docs/images/eval-resolve-default-model.png
cp "$out/params/params.png" docs/images/eval-params-default-model.png
for e in goals-1.5b goals-0.5b resolve params resolve-scenario-goal params-scenario-goal; do
  echo "=== $e ($out/$e/table.md)"
  cat "$out/$e/table.md"
done
