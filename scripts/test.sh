#!/usr/bin/env bash
# Every test of betr. (So far the tests need only a Rust toolchain and the goal dataset in
# ../shared; stages that need system packages install them from here.)
# Usage: bash scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -d ../shared/datasets/llm-obtea ]; then
  echo "error: ../shared/datasets/llm-obtea is missing; the tests read the goal dataset from there" >&2
  exit 2
fi

cargo test --locked
