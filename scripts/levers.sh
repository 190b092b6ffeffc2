#!/usr/bin/env bash
# What each part of reading earns: the held-out suite read once with every part on, then
# again with each misreading detector left out, all of them left out, and the request read
# whole. Every run shares one cassette reused
# (--reuse-cassette), so a run asks the model only the questions that part changes.
# Prints the lever table of docs/EVAL.md (scripts/lever_table.py).
#
#   bash scripts/levers.sh [OUT_DIR]     (default: eval-results/levers)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-eval-results/levers}
mkdir -p "$out"
betr=${BETR:-target/debug/betr}
[ -x "$betr" ] || cargo build --locked
# Every set but the 100 tuned cafe requests, and the two never tuned to.
python3 - "$out" <<'PY'
import sys
text = open("docs/eval-suite.toml").read()
sets = text.split("[[set]]")[1:]
def keep(names):
    return "[[set]]" + "[[set]]".join(s for s in sets if any(f'name = "{n}"' in s for n in names))
open(f"{sys.argv[1]}/heldout-suite.toml", "w").write(keep(["cafe-heldout", "cell", "greenhouse"]))
PY
common=(--threads "${BETR_THREADS:-2}" --cassette "$out/cassette.jsonl" --reuse-cassette)
run() { local name=$1 suite=$2; shift 2; "$betr" eval goals --suite "$out/$suite" "${common[@]}" "$@" --out "$out/$name" > "$out/$name.log" 2>&1; }
run base heldout-suite.toml
detectors=$("$betr" eval goals --without-misreading '?' 2>&1 | sed -n 's/.*the misreadings are //p' | tr -d ',')
all=()
rows=()
for d in $detectors; do
  run "without-$d" heldout-suite.toml --without-misreading "$d"
  all+=(--without-misreading "$d")
  rows+=("without $d=$out/without-$d")
done
run without-all heldout-suite.toml "${all[@]}"
run whole-request heldout-suite.toml --whole-request
python3 scripts/lever_table.py "$out/base" "${rows[@]}" "every detector left out=$out/without-all" \
  "request read whole=$out/whole-request"
