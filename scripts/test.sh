#!/usr/bin/env bash
# Every test of betr. The tests need a Rust toolchain, the goal dataset in ../shared, and
# a few Debian packages that scripts/setup.sh installs when missing. Tests that run the
# embedded LLM fetch it into the cache on first use.
# Usage: bash scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -d ../shared/datasets/llm-obtea ]; then
  echo "error: ../shared/datasets/llm-obtea is missing; the tests read the goal dataset from there" >&2
  exit 2
fi

# Build packages, plus spin (cross-checks `betr verify`) and tmux (drives the real binary).
bash scripts/setup.sh --test

cargo test --locked
