#!/usr/bin/env bash
# Every test of betr. The tests need a Rust toolchain, the goal dataset in ../shared, the
# SPIN model checker, tmux and python3-venv (installed here with apt when missing).
# Usage: bash scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -d ../shared/datasets/llm-obtea ]; then
  echo "error: ../shared/datasets/llm-obtea is missing; the tests read the goal dataset from there" >&2
  exit 2
fi

# The SPIN model checker cross-checks `betr verify` (tests/verify_scenarios.rs).
if ! command -v spin >/dev/null 2>&1; then
  echo "spin is missing: installing the Debian package" >&2
  if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
  $SUDO apt-get update
  $SUDO apt-get install -y spin
fi

# tmux runs the real binary as a person would (tests/tui_tmux.rs).
if ! command -v tmux >/dev/null 2>&1; then
  echo "tmux is missing: installing the Debian package" >&2
  if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
  $SUDO apt-get update
  $SUDO apt-get install -y tmux
fi

# The 3D view's end-to-end test (tests/viz_rrd.rs) checks a recording with the viewer's
# own CLI, pip-installed once into a virtual environment under target/.
if ! python3 -c "import venv, ensurepip" >/dev/null 2>&1; then
  echo "python3-venv is missing: installing the Debian package" >&2
  if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
  $SUDO apt-get update
  $SUDO apt-get install -y python3-venv
fi

cargo test --locked
