#!/usr/bin/env bash
# Reading with the scenario's written example pool, with only the pool betr makes from the
# domain for a scenario that writes none, and with no pool, on the sets the reading was
# not written from (docs/EVAL.md, "Reading that learns"). Every run shares one cassette
# (--reuse-cassette): pass the cassette of a suite run to answer the written pool's
# requests from it.
#
#   bash scripts/example_pools.sh [OUT_DIR] [CASSETTE]
#     (default: eval-results/pools, OUT_DIR/cassette.jsonl)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-eval-results/pools}
cassette=${2:-$out/cassette.jsonl}
mkdir -p "$out"
betr=${BETR:-target/release/betr}
[ -x "$betr" ] || cargo build --release --locked
python3 - "$out" <<'PY'
import sys
text = open("docs/eval-suite.toml").read()
sets = text.split("[[set]]")[1:]
keep = ["cafe-heldout-2", "greenhouse-2", "lab", "warehouse", "hospital"]
chosen = [s for s in sets if any(f'name = "{n}"' in s for n in keep)]
open(f"{sys.argv[1]}/suite.toml", "w").write("[[set]]" + "[[set]]".join(chosen))
PY
common=(--backend local --threads "${BETR_THREADS:-2}" --cassette "$cassette" --reuse-cassette)
for pool in written made none; do
  "$betr" eval goals --suite "$out/suite.toml" --example-pool "$pool" "${common[@]}" \
    --out "$out/$pool" > "$out/$pool.log" 2>&1
  echo "=== $pool pool ($out/$pool/suite.md)"
  cat "$out/$pool/suite.md"
done
