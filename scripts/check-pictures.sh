#!/usr/bin/env bash
# Checks that the terminal pictures in docs/images/ (made by scripts/screenshots.sh)
# render in a browser as the terminal showed them: each workbench-*.svg and monitor-*.svg
# is rendered in
# headless Chromium (Debian's `chromium`) and the character grid Chromium laid out is
# compared with the terminal's plain text of the same capture (NAME.txt), cell by
# cell (scripts/picture_check.py says what counts as a mismatch). A PNG of each rendered
# picture goes to target/pictures/ for a person to look at.
# Usage: bash scripts/check-pictures.sh [OPTIONS] [SVG...]
#        (the pictures docs/images/workbench-*.svg and monitor-*.svg unless named; OPTIONS are
#        picture_check.py's: --font FAMILY renders with another font, --max N shows more
#        mismatches, --png-dir DIR, --port PORT; installs chromium with apt when missing)
# Exit status 0 with one line per picture when all match, 1 with the mismatches (picture,
# row, column, expected and rendered character) when one does not, 2 when the check
# cannot run.
set -euo pipefail
cd "$(dirname "$0")/.."

. scripts/chromium-env.sh
needs_chromium
viewer_venv "import websocket" "websocket-client==1.8.0"

options=()
pictures=()
while [ $# -gt 0 ]; do
  case "$1" in
    --font|--max|--png-dir|--port) options+=("$1" "${2:?error: $1 needs a value}"); shift 2 ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    -*) echo "error: unknown option $1 (see: bash scripts/check-pictures.sh --help)" >&2; exit 2 ;;
    *) pictures+=("$1"); shift ;;
  esac
done
if [ ${#pictures[@]} -eq 0 ]; then
  shopt -s nullglob
  pictures=(docs/images/workbench-*.svg docs/images/monitor-*.svg)
  shopt -u nullglob
  [ ${#pictures[@]} -gt 0 ] || { echo "error: no docs/images/workbench-*.svg or monitor-*.svg to check" >&2; exit 2; }
fi
exec "$venv/bin/python" scripts/picture_check.py --png-dir "$target/pictures" "${options[@]}" "${pictures[@]}"
