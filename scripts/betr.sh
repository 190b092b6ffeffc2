#!/usr/bin/env bash
# The main job: the workbench on the default scenario (scenario 1, red cube on the blue
# cube) with the embedded LLM. The first run installs the build packages, builds betr and
# fetches the model (about 1.1 GB, with a progress bar). Arguments are passed to betr.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
exec cargo run --release --locked -- "$@"
