#!/usr/bin/env bash
# Installs the Debian packages betr needs, only those that are missing, in one apt run.
#   bash scripts/setup.sh          what building and running betr needs
#   bash scripts/setup.sh --test   plus what the tests need
# Safe to run again: it does nothing when everything is there.
set -euo pipefail

# Building: llama.cpp (the embedded LLM) and CTranslate2 (speech-to-text) are compiled
# with cmake and a C++ compiler, llama.cpp's Rust bindings are generated with libclang,
# cpal links ALSA (pkg-config finds it). Charts draw their labels with DejaVu Sans.
packages=(cmake g++ pkg-config libclang-dev libasound2-dev fonts-dejavu-core)
if [ "${1:-}" = "--test" ]; then
  # spin cross-checks `betr verify`; tmux drives the real binary as a person would;
  # espeak-ng speaks the instructions the dictation tests transcribe; graphviz renders
  # the DOT export; mount makes the small full filesystem of the full-disk test (as root).
  packages+=(spin tmux espeak-ng graphviz mount)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "installing Debian packages: ${missing[*]}" >&2
if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >&2
