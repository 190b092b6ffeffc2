#!/usr/bin/env bash
# Every test of betr. The tests need a Rust toolchain, the goal dataset in ../shared, and
# a few Debian packages that scripts/setup.sh installs when missing. Tests that run the
# embedded LLM or speech-to-text fetch their models into the cache on first use.
# Usage: bash scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -d ../shared/datasets/llm-obtea ]; then
  echo "error: ../shared/datasets/llm-obtea is missing; the tests read the goal dataset from there" >&2
  exit 2
fi

# Build packages, plus spin, tmux, espeak-ng and graphviz for the tests.
bash scripts/setup.sh --test

# The 3D view's end-to-end test (tests/viz_rrd.rs) checks a recording with the viewer's
# own CLI, and tests/btcpp_runs.rs ticks the exported trees in BehaviorTree.CPP's Python
# bindings (scripts/btcpp-venv.sh), each pip-installed once into a virtual environment
# under target/.
if ! python3 -c "import venv, ensurepip" >/dev/null 2>&1; then
  echo "python3-venv is missing: installing the Debian package" >&2
  if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
  $SUDO apt-get update
  $SUDO apt-get install -y python3-venv
fi

# A full test build with its Python environments and models takes about 12 GB; say so
# before the build runs out of room halfway.
free_kb=$(df -Pk . | awk 'NR==2 {print $4}')
if [ -n "$free_kb" ] && [ "$free_kb" -lt $((12 * 1024 * 1024)) ]; then
  echo "warning: $((free_kb / 1024)) MB free on the disk holding $(pwd); a full test build needs about 12 GB" >&2
fi

cargo test --locked
