#!/usr/bin/env bash
# Regenerates tests/fixtures/motion/yumi_fk.json: the YuMi's forward kinematics computed by
# Pinocchio (`pin` from the package index, installed once into target/motion-venv) on the
# URDF betr fetches (`cargo test --lib robot::` installs it into the model cache).
# Usage: bash scripts/motion-fixtures.sh [URDF]
set -euo pipefail
cd "$(dirname "$0")/.."
cache="${BETR_MODEL_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/betr/models}"
urdf="${1:-$cache/yumi_description-rtb-data-1.0.1/urdf/yumi.urdf}"
if [ ! -f "$urdf" ]; then
  echo "error: $urdf is missing; run \`cargo test --lib robot::\` once to fetch the YuMi's description" >&2
  exit 2
fi
venv="${MOTION_VENV:-target/motion-venv}"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
if ! "$venv/bin/python" -c "import pinocchio" >/dev/null 2>&1; then
  "$venv/bin/pip" install --quiet pin
fi
mkdir -p tests/fixtures/motion
"$venv/bin/python" scripts/motion_fixtures.py "$urdf" tests/fixtures/motion/yumi_fk.json
