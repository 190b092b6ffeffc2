# Sourced by the scripts that drive headless Chromium (check-pictures.sh,
# viewer-screenshots.sh).
#   needs_chromium            installs Debian's chromium with apt when it is missing
#   viewer_venv CHECK PKG...  sets `target` (CARGO_TARGET_DIR or target) and `venv`
#                             ($target/viewer-venv, the Python with the DevTools client),
#                             installing PKG... into it, under a lock, when the Python
#                             statement CHECK fails there

needs_chromium() {
  command -v chromium >/dev/null && return 0
  echo "installing Debian's chromium for the headless browser" >&2
  local sudo="sudo"
  [ "$(id -u)" -eq 0 ] && sudo=""
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq chromium >&2
}

viewer_venv() {
  local check="$1"
  shift
  target="${CARGO_TARGET_DIR:-target}"
  mkdir -p "$target"
  venv="$target/viewer-venv"
  exec 9>"$venv.lock"
  flock 9
  if ! "$venv/bin/python" -c "$check" >/dev/null 2>&1; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet --disable-pip-version-check "$@"
  fi
  flock -u 9
}
