#!/usr/bin/env bash
# Build llama.cpp's own `llama-bench` linked against the very llama.cpp libraries betr's
# build made (the static ggml, llama and common libraries in the llama-cpp-sys crate's
# build directory), its two source files compiled with the flags that build used (read
# from its CMakeCache.txt), so `betr bench model` compares betr with llama.cpp on the same
# machine code. The crate leaves out the tools' sources, so llama-bench's files come from
# the llama.cpp vendored in the llama-cpp-python sdist on PyPI (pinned below; its llama.h
# and ggml.h match the crate's). Prints the binary's path.
# Usage: scripts/llama-bench.sh [PROFILE_DIR]   (default: target/release)
set -euo pipefail
cd "$(dirname "$0")/.."
profile_dir="${1:-target/release}"
sdist_version=0.3.36
sdist_sha256=832db0699007f1be95a7e41ef12e88926b02ba836461e36a36372db2760c1a2e
sdist_url=https://files.pythonhosted.org/packages/ec/e9/e7de2b0463ea3ffbf0ede6cb21b58c1258a8f6521aae45ca773a59fe7cf3/llama_cpp_python-0.3.36.tar.gz

cache=$(ls -t "$profile_dir"/build/llama-cpp-sys-2-*/out/build/CMakeCache.txt 2>/dev/null | head -1 || true)
if [ -z "$cache" ]; then
  echo "llama-bench: no llama.cpp build of betr under $profile_dir (build betr first: cargo build --release)" >&2
  exit 2
fi
build=$(dirname "$cache")
value() { grep -E "^$1:" "$cache" | head -1 | cut -d= -f2-; }
source_dir=$(value CMAKE_HOME_DIRECTORY)
if [ ! -f "$source_dir/include/llama.h" ]; then
  echo "llama-bench: $source_dir (named in $cache) is not a llama.cpp source tree" >&2
  exit 2
fi
out="$profile_dir/llama-bench"
mkdir -p "$out" target/llama-bench

# llama-bench's sources, once for every profile.
tool=target/llama-bench/tool
if [ ! -f "$tool/llama-bench.cpp" ] || [ ! -f "$tool/main.cpp" ]; then
  echo "llama-bench: fetching its sources (llama-cpp-python $sdist_version sdist, 77 MB)" >&2
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  python3 - "$sdist_url" "$tmp/sdist.tar.gz" <<'PY'
import sys, urllib.request
url, path = sys.argv[1], sys.argv[2]
for attempt in range(3):
    try:
        urllib.request.urlretrieve(url, path)
        break
    except OSError as e:
        if attempt == 2:
            sys.exit(f"llama-bench: cannot fetch {url}: {e}")
PY
  echo "$sdist_sha256  $tmp/sdist.tar.gz" | sha256sum -c --quiet - || {
    echo "llama-bench: the sdist does not match its SHA-256" >&2; exit 2; }
  prefix="llama_cpp_python-$sdist_version/vendor/llama.cpp/tools/llama-bench"
  tar xzf "$tmp/sdist.tar.gz" -C "$tmp" "$prefix/llama-bench.cpp" "$prefix/main.cpp"
  rm -rf "$tool.partial" && mkdir -p "$tool.partial"
  cp "$tmp/$prefix/llama-bench.cpp" "$tmp/$prefix/main.cpp" "$tool.partial/"
  rm -rf "$tool" && mv "$tool.partial" "$tool"
fi

build_type=$(value CMAKE_BUILD_TYPE)
flags="$(value CMAKE_CXX_FLAGS) $(value "CMAKE_CXX_FLAGS_${build_type^^}")"
mapfile -t libs < <(find "$build" -name '*.a' | sort)
system=(-lpthread)
if [ "$(value GGML_OPENMP_ENABLED)" = "ON" ]; then flags="$flags -fopenmp"; fi
if [ "$(value LLAMA_OPENSSL)" = "ON" ]; then
  system+=("$(value OPENSSL_SSL_LIBRARY)" "$(value OPENSSL_CRYPTO_LIBRARY)")
fi
# Rebuilt when betr's libraries or flags change.
stamp=$( (echo "$flags"; stat -c '%n %s %Y' "${libs[@]}" "$tool"/*.cpp) | sha256sum | cut -c1-16)
binary="$out/llama-bench"
if [ -x "$binary" ] && [ "$(cat "$out/settings" 2>/dev/null)" = "$stamp" ]; then
  echo "$binary"
  exit 0
fi
echo "llama-bench: compiling against betr's llama.cpp in $build" >&2
rm -f "$out/settings"
# shellcheck disable=SC2086 # the flags are a list of words
c++ $flags -std=c++17 -w \
  -I"$source_dir/include" -I"$source_dir/ggml/include" -I"$source_dir/common" -I"$source_dir/vendor" \
  "$tool/llama-bench.cpp" "$tool/main.cpp" -o "$binary.partial" \
  -Wl,--start-group "${libs[@]}" -Wl,--end-group "${system[@]}"
mv "$binary.partial" "$binary"
echo "$stamp" > "$out/settings"
echo "$binary"
