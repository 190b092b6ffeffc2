#!/usr/bin/env bash
# Fuzz betr's readers of outside input (docs/FUZZ.md), built in release.
# Usage: bash scripts/fuzz.sh TARGET|all N [--seed S] [--start I] [--out DIR]
#   TARGET: goal, reply, tree, btcpp, scenario, policy, cassette, journal, wav, recording
# Failing inputs are saved under target/fuzz/TARGET/ (or --out); the exit code is 1 when
# an input failed.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ $# -lt 2 ]; then
  echo "usage: bash scripts/fuzz.sh TARGET|all N [--seed S] [--start I] [--out DIR]" >&2
  exit 2
fi
target=$1
inputs=$2
shift 2

cargo build --release --locked
# Run a copy of this run's own: another build during a long run would replace the binary
# under it, and runs side by side (one target per core) must not overwrite each other's.
mkdir -p target/fuzz
bin="target/fuzz/betr-$$"
cp target/release/betr "$bin"
trap 'rm -f "$bin"' EXIT
"$bin" fuzz "$target" "$inputs" "$@"
