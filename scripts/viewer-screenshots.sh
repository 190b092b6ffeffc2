#!/usr/bin/env bash
# Screenshots of the 3D view for the README: rerun's web viewer (`rerun --serve-web FILE`,
# rerun-sdk 0.36.3 in target/viewer-venv) serving what the real `betr` recorded (`--rrd`),
# rendered in headless Chromium (Debian's `chromium`, software WebGL) and captured through
# the DevTools protocol (scripts/viewer_screenshot.py) into docs/images/:
#   viewer-failure.png   scenario 1's planned tree run: the grasp of the blue cube fails,
#                        its way down red where the red cube is in it (with the YuMi's
#                        description cached: the robot's meshes, the red cube that blocks
#                        the arm drawn red)
#   viewer-repaired.png  the same tree repaired with the fix, run to success
#   viewer-mujoco.png    scenario 1 with the red cube the camera missed, run in MuJoCo
#                        (--executor mujoco): the arm comes down onto the red cube, and
#                        the twin's prediction is drawn faint beside reality's cubes
# Usage: bash scripts/viewer-screenshots.sh [NAME.png...]   (only those; installs chromium with apt when missing;
#        BETR=path/to/betr uses that binary instead of building one; the viewer listens
#        on VIEWER_GRPC_PORT and VIEWER_PAGE_PORT, 9931 and 9932 unless set; VIEWER_WAIT:
#        seconds the page is given to draw, 30 unless set)
set -euo pipefail
cd "$(dirname "$0")/.."

. scripts/chromium-env.sh
needs_chromium
viewer_venv "import websocket, rerun; assert rerun.__version__ == '0.36.3'" \
  "rerun-sdk==0.36.3" "websocket-client==1.8.0"

if [ -z "${BETR:-}" ]; then
  cargo build --locked
fi
betr="$(realpath "${BETR:-$target/debug/betr}")"
venv="$(realpath "$venv")"
out="docs/images"
mkdir -p "$out"
work="$(mktemp -d)"
viewer=""
stop_viewer() {
  if [ -n "$viewer" ]; then
    # The venv's `rerun` is a Python launcher of the viewer's binary: stop both (their
    # own process group, made by setsid).
    kill -- "-$viewer" 2>/dev/null || true
    wait "$viewer" 2>/dev/null || true
    viewer=""
  fi
}
trap 'stop_viewer; rm -rf "$work"' EXIT

# The recording is served by a viewer of its own on ports no live session streams to
# (betr's `--viewer web` uses 9876 and 9090, where another session's stream would mix in).
grpc_port="${VIEWER_GRPC_PORT:-9931}"
page_port="${VIEWER_PAGE_PORT:-9932}"
for port in "$grpc_port" "$page_port"; do
  if (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
    echo "error: port $port is taken; set VIEWER_GRPC_PORT and VIEWER_PAGE_PORT to free ones" >&2
    exit 2
  fi
done

scenario="$PWD/scenarios/cell/red_on_blue.toml"
fix='~"any object" on "blue cube"'

# One capture: the session recorded to an .rrd, a fresh web viewer serving it (started
# here, so it is stopped here), then the page once it has drawn.
capture() {
  local png="$1"
  shift
  if [ "${#wanted[@]}" -gt 0 ] && [[ ! " ${wanted[*]} " =~ " $png " ]]; then
    return
  fi
  local rrd="$work/${png%.png}.rrd"
  (cd "$work" && "$betr" "$@" --rrd "$rrd" >"$work/betr.out" 2>"$work/betr.err") || true
  if [ ! -s "$rrd" ]; then
    echo "error: betr wrote no recording:" >&2
    cat "$work/betr.err" >&2
    exit 1
  fi
  PATH="$venv/bin:$PATH" setsid rerun --serve-web "$rrd" --port "$grpc_port" \
    --web-viewer-port "$page_port" >"$work/rerun.log" 2>&1 &
  viewer=$!
  for _ in $(seq 100); do
    (exec 3<>"/dev/tcp/127.0.0.1/$page_port") 2>/dev/null && break
    sleep 0.2
  done
  local url="http://127.0.0.1:$page_port/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A$grpc_port%2Fproxy"
  "$venv/bin/python" scripts/viewer_screenshot.py "$url" "$out/$png" --wait "${VIEWER_WAIT:-30}" --size 1920x1080
  stop_viewer
  echo "$out/$png" >&2
}

wanted=("$@")
capture viewer-failure.png run "$scenario"
capture viewer-repaired.png repair "$scenario" --add "$fix"
capture viewer-mujoco.png run "$PWD/tests/fixtures/scenarios/red_unseen.toml" --executor mujoco
