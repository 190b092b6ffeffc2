#!/usr/bin/env bash
# Every test of betr, in two tiers (docs/BUILD.md, "Tests"):
#   fast  the library's unit tests, the fast test binary (tests/fast: the fake and
#         scripted models, fixtures, snapshots, fuzz seeds, the binary's commands) and the
#         doc tests; no language or speech model, no tmux, no Python
#         environment, no killed child process. Run it after every change.
#   slow  the slow test binary (tests/slow: the real language model and Whisper, the tmux
#         suites, the pip anchors, the kill tests, the arms end to end), a module at a time.
# The tests need a Rust toolchain, the goal dataset in ../shared, and a few Debian
# packages that scripts/setup.sh installs when missing. Tests that run the embedded LLM or
# speech-to-text fetch their models into the cache on first use.
# Usage: bash scripts/test.sh [fast | slow [MODULE...]]
#   no argument: the fast tier, then the slow; `slow bench_cmd viz_rrd`: those modules of
#   the slow tier only (a single test: cargo test --test slow -- NAME).
set -euo pipefail
cd "$(dirname "$0")/.."

tier="${1:-all}"
case "$tier" in
  fast | slow | all) ;;
  *)
    echo "usage: bash scripts/test.sh [fast | slow [MODULE...]]  (no argument: both, the fast tier first)" >&2
    exit 2
    ;;
esac
[ $# -gt 0 ] && shift
if [ $# -gt 0 ] && [ "$tier" != slow ]; then
  echo "error: only the slow tier takes module names" >&2
  exit 2
fi

if [ ! -d ../shared/datasets/llm-obtea ]; then
  echo "error: ../shared/datasets/llm-obtea is missing; the tests read the goal dataset from there" >&2
  exit 2
fi

# Build packages, plus spin, tmux, espeak-ng, graphviz and mount for the tests.
bash scripts/setup.sh --test

# The 3D view's end-to-end test (tests/slow/viz_rrd.rs) checks a recording with the
# viewer's own CLI, and tests/slow/btcpp_runs.rs ticks the exported trees in
# BehaviorTree.CPP's Python bindings (scripts/btcpp-venv.sh), each pip-installed once into
# a virtual environment under target/.
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

fast() {
  cargo test --locked --lib --test fast
  cargo test --locked --doc
}

# The slow binary's modules (its former test files) one after another, each module's tests
# side by side, as the separate binaries ran: a module's tests share its models and
# venvs, and the tmux suites, the model's threads and the kill tests' timings do not
# compete with another module's. Every module runs; the failed ones are listed at the end.
slow() {
  # Built once; the binary is then run by itself, from the crate root as cargo runs it, so
  # the modules do not each wait for cargo's lock on the target directory.
  local bin
  bin=$(cargo test --locked --test slow --no-run --message-format=json |
    python3 -c 'import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m["target"]["name"] == "slow" and m.get("executable"):
        print(m["executable"])')
  if [ ! -x "$bin" ]; then
    echo "error: cargo built no slow test binary" >&2
    return 1
  fi
  local list modules failed=() module names
  list=$("$bin" --list --format terse | sed -n 's/: test$//p')
  if [ -z "$list" ]; then
    echo "error: the slow test binary lists no tests" >&2
    return 1
  fi
  modules=$(printf '%s\n' "$list" | cut -d: -f1 | sort -u)
  if [ $# -gt 0 ]; then
    for module in "$@"; do
      if ! printf '%s\n' "$modules" | grep -qx "$module"; then
        echo "error: the slow tier has no module $module; it has: $(echo $modules)" >&2
        return 2
      fi
    done
    modules="$*"
  fi
  for module in $modules; do
    mapfile -t names < <(printf '%s\n' "$list" | grep "^${module}::")
    echo "=== slow: $module (${#names[@]} tests)" >&2
    local start=$SECONDS
    if ! "$bin" --exact "${names[@]}"; then
      failed+=("$module")
    fi
    echo "=== slow: $module took $((SECONDS - start)) s" >&2
  done
  if [ ${#failed[@]} -gt 0 ]; then
    echo "error: slow tier modules with failures: ${failed[*]}" >&2
    return 1
  fi
}

case "$tier" in
  fast) fast ;;
  slow) slow "$@" ;;
  all)
    fast
    slow
    ;;
esac
