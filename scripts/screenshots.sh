#!/usr/bin/env bash
# Screenshots of the workbench for the README: the real `betr tui` in a real terminal
# (tmux, 140×45), driven with keys as a person would on scenario 1 with the embedded
# default model, captured with its colours at three moments and drawn as SVG images into
# docs/images/: the planned tree, the failure with the proposal awaiting approval, and
# success after the repair. Each picture comes with the terminal's plain text of the same
# capture (NAME.txt beside NAME.svg), which `bash scripts/check-pictures.sh` compares with
# the picture as a browser renders it. `monitor` draws docs/images/monitor-watching.svg:
# `betr monitor` following a tree ticked in BehaviorTree.CPP itself (scripts/btcpp_publisher.py
# in the venv scripts/btcpp-venv.sh makes). Run it again whenever the screens change.
# Usage: bash scripts/screenshots.sh [workbench | monitor]   (no argument: both; needs
#        tmux and python3; the workbench's fetch the model once)
#        BETR=path/to/betr bash scripts/screenshots.sh   (a betr already built, e.g. the
#        dev profile's target/debug/betr, instead of building the release one)
set -euo pipefail
cd "$(dirname "$0")/.."
which="${1:-all}"
case "$which" in
  workbench | monitor | all) ;;
  *) echo "usage: bash scripts/screenshots.sh [workbench | monitor]" >&2; exit 2 ;;
esac
command -v tmux >/dev/null || { echo "error: tmux is needed (apt install tmux)" >&2; exit 2; }
if [ -n "${BETR:-}" ]; then
  betr="$(cd "$(dirname "$BETR")" && pwd)/$(basename "$BETR")"
else
  cargo build --release --locked
  betr="$PWD/target/release/betr"
fi
out="docs/images"
mkdir -p "$out"
betr_dir="$(mktemp -d)"
socket="betr-screenshots-$$"
trap 'tmux -L "$socket" kill-server 2>/dev/null || true; rm -rf "$betr_dir"' EXIT

screen() { tmux -L "$socket" capture-pane -p -t betr; }
# Wait until the screen shows every argument; give up after 300 s (the model is slow on
# two cores).
wait_for() {
  local deadline=$((SECONDS + 300))
  while :; do
    local s
    s="$(screen)"
    local all=1
    for want in "$@"; do
      [[ "$s" == *"$want"* ]] || all=0
    done
    [ "$all" = 1 ] && return 0
    if [ "$SECONDS" -ge "$deadline" ]; then
      echo "error: timed out waiting for: $*" >&2
      echo "$s" >&2
      exit 1
    fi
    sleep 0.2
  done
}
# One capture drawn as $out/NAME.svg, its plain text as $out/NAME.txt.
shot() {
  tmux -L "$socket" capture-pane -e -p -t betr |
    python3 scripts/ansi_to_svg.py --text "$out/$1.txt" > "$out/$1.svg"
  echo "wrote $out/$1.svg and $out/$1.txt"
}
keys() { tmux -L "$socket" send-keys -t betr "$@"; }

workbench() {
  # The model is fetched before the terminal opens (with its progress bar here), so the
  # screens show the workbench and not a download.
  "$betr" model fetch

  tmux -L "$socket" new-session -d -s betr -x 140 -y 45 \
    "cd '$betr_dir' && XDG_STATE_HOME='$betr_dir/state' XDG_DATA_HOME='$betr_dir/data' '$betr' tui '$PWD/scenarios/cell/red_on_blue.toml' --policy-dir '$betr_dir/policies'; sleep 60"

  wait_for "Behavior tree" "press i to type an instruction"
  keys i
  wait_for "Instruction or goal"
  keys -l "Put the blue cube on the green cube"
  keys Enter
  wait_for 'Goal: "blue cube" on "green cube"' '[o] Fallback'
  sleep 0.5
  shot workbench-planned

  for _ in $(seq 1 10); do
    keys Space
    sleep 0.3
    [[ "$(screen)" == *"◀ failed"* ]] && break
  done
  wait_for "◀ failed" "Proposal for grasp" "awaiting approval"
  sleep 0.5
  shot workbench-proposal

  keys a
  wait_for "repaired:"
  keys r
  wait_for "SUCCESS"
  sleep 0.5
  shot workbench-success
  keys q
  tmux -L "$socket" kill-session -t betr 2>/dev/null || true
}

# betr monitor following BehaviorTree.CPP: the test publisher ticks its tree every 20 ms
# from the line sent on its input until the input closes.
monitor() {
  local python port=1677 fifo="$betr_dir/publisher-input"
  python="$(bash scripts/btcpp-venv.sh)"
  mkfifo "$fifo"
  "$python" scripts/btcpp_publisher.py "$port" 0 <"$fifo" >"$betr_dir/publisher.log" &
  local publisher=$!
  exec 8>"$fifo"
  tmux -L "$socket" new-session -d -s betr -x 120 -y 30 \
    "cd '$betr_dir' && XDG_STATE_HOME='$betr_dir/state' '$betr' monitor :$port; sleep 60"
  wait_for "status changes" "watching 127.0.0.1:$port"
  echo go >&8
  sleep 2
  # The root selected (following stops), so the node pane shows the main blackboard.
  keys Home
  wait_for "grasps = " "not following"
  sleep 1
  shot monitor-watching
  keys q
  exec 8>&-
  wait "$publisher" || true
  tmux -L "$socket" kill-session -t betr 2>/dev/null || true
}

case "$which" in
  workbench) workbench ;;
  monitor) monitor ;;
  all)
    workbench
    monitor
    ;;
esac
