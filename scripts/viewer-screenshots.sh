#!/usr/bin/env bash
# Screenshots of the 3D view for the README: rerun's web viewer (`rerun --serve-web`,
# rerun-sdk 0.36.3 in target/viewer-venv) fed by the real `betr` through `--viewer web`,
# rendered in headless Chromium (Debian's `chromium`, software WebGL) and captured through
# the DevTools protocol (scripts/viewer_screenshot.py) into docs/images/:
#   viewer-failure.png   scenario 1's planned tree run: the grasp of the blue cube fails,
#                        its way down red where the red cube is in it
#   viewer-repaired.png  the same tree repaired with the fix, run to success
# Usage: bash scripts/viewer-screenshots.sh   (installs chromium with apt when missing;
#        BETR=path/to/betr uses that binary instead of building one)
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v chromium >/dev/null; then
  echo "installing Debian's chromium for the headless browser" >&2
  if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium >&2
fi

target="${CARGO_TARGET_DIR:-target}"
mkdir -p "$target"
venv="$target/viewer-venv"
exec 9>"$venv.lock"
flock 9
if ! "$venv/bin/python" -c "import websocket, rerun; assert rerun.__version__ == '0.36.3'" >/dev/null 2>&1; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet --disable-pip-version-check "rerun-sdk==0.36.3" "websocket-client==1.8.0"
fi
flock -u 9

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

for port in 9876 9090; do
  if (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
    echo "error: port $port is taken; betr's web viewer listens on 9876 (gRPC) and 9090 (page)" >&2
    exit 2
  fi
done

scenario="$PWD/scenarios/cell/red_on_blue.toml"
fix='~"any object" on "blue cube"'

# One capture: a fresh web viewer (started here, so it is stopped here; betr finds it
# listening and streams to it), the session, then the page once it has drawn.
capture() {
  local png="$1"
  shift
  PATH="$venv/bin:$PATH" setsid rerun --serve-web --port 9876 --web-viewer-port 9090 >"$work/rerun.log" 2>&1 &
  viewer=$!
  for _ in $(seq 100); do
    (exec 3<>/dev/tcp/127.0.0.1/9090) 2>/dev/null && break
    sleep 0.2
  done
  (cd "$work" && PATH="$venv/bin:$PATH" "$betr" "$@" --viewer web >"$work/betr.out" 2>"$work/betr.err") || true
  local url
  url="$(sed -n 's/^3D view: open //p' "$work/betr.err")"
  if [ -z "$url" ]; then
    echo "error: betr printed no web viewer address:" >&2
    cat "$work/betr.err" >&2
    exit 1
  fi
  "$venv/bin/python" scripts/viewer_screenshot.py "$url" "$out/$png" --wait 30 --size 1920x1080
  stop_viewer
  echo "$out/$png" >&2
}

capture viewer-failure.png run "$scenario"
capture viewer-repaired.png repair "$scenario" --add "$fix"
