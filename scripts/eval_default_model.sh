#!/usr/bin/env bash
# Run the three experiments of `betr eval` with the embedded default model and copy the
# tables and charts into docs/ (docs/EVAL.md, "Results with the embedded default model").
# Needs `--backend local` (the embedded model, issue 5) and the model in the cache
# (`betr model fetch`). Usage: bash scripts/eval_default_model.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
runs="${1:-10}"
out="eval-results/default-model"
mkdir -p "$out" docs/images
cargo build --release --locked
betr=target/release/betr
# Each command resumes from its directory if interrupted: run this script again.
"$betr" eval goals --backend local --out "$out/goals"
"$betr" eval resolve --backend local --runs "$runs" --out "$out/resolve"
"$betr" eval params --backend local --runs "$runs" --out "$out/params"
cp "$out/goals/accuracy.png" docs/images/eval-goals-default-model.png
cp "$out/resolve/resolve.png" docs/images/eval-resolve-default-model.png
cp "$out/params/params.png" docs/images/eval-params-default-model.png
for e in goals resolve params; do
  echo "=== $e ($out/$e/table.md)"
  cat "$out/$e/table.md"
done
