#!/usr/bin/env bash
# Installs BehaviorTree.CPP's Python bindings (`behaviortreepy` from the package index,
# bindings of the released C++ library) into a virtual environment under target/, once.
# tests/slow/btcpp_runs.rs runs the exported trees in it through scripts/btcpp_driver.py.
#   bash scripts/btcpp-venv.sh [VENV]     VENV defaults to $CARGO_TARGET_DIR/btcpp-venv
# Prints the venv's python on success. Safe to run again and from several processes at
# once: the install runs under a lock and does nothing when the right version is there.
set -euo pipefail
cd "$(dirname "$0")/.."

version="0.1.4"
venv="${1:-${CARGO_TARGET_DIR:-target}/btcpp-venv}"
python="$venv/bin/python"
check="import behaviortreepy, importlib.metadata as m; assert m.version('behaviortreepy') == '$version'"

if ! mkdir -p "$(dirname "$venv")" 2>/dev/null; then
  echo "error: cannot create the folder of $venv" >&2
  exit 1
fi
exec 9>"$venv.lock"
flock 9
if ! "$python" -c "$check" >/dev/null 2>&1; then
  if ! python3 -c "import venv, ensurepip" >/dev/null 2>&1; then
    echo "error: python3 cannot make a virtual environment; install the Debian package python3-venv" >&2
    exit 1
  fi
  echo "installing behaviortreepy==$version into $venv" >&2
  python3 -m venv "$venv" >&2
  if ! "$venv/bin/pip" install --quiet --disable-pip-version-check "behaviortreepy==$version" >&2; then
    echo "error: pip could not install behaviortreepy==$version from the package index into $venv" >&2
    exit 1
  fi
  if ! "$python" -c "$check" >&2; then
    echo "error: behaviortreepy $version is not importable in $venv after installing" >&2
    exit 1
  fi
fi
echo "$python"
