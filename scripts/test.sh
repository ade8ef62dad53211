#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite through ctest.
# Arguments name CMake presets to build and test (default: dev, a debug build with warnings as
# errors); e.g. `scripts/test.sh asan-ubsan tsan` runs the suite under the sanitizers.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh --with-browser --with-broker
# Rebuilds reuse compiled objects through ccache, also from another checkout of the same tree:
# paths under the checkout are hashed relative to it.
if command -v ccache >/dev/null && [[ -z "${CMAKE_CXX_COMPILER_LAUNCHER:-}" ]]; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_C_COMPILER_LAUNCHER=ccache
  export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true
fi
presets=("$@")
((${#presets[@]} > 0)) || presets=(dev)
for preset in "${presets[@]}"; do
  echo "== $preset: build" >&2
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset"
  echo "== $preset: test" >&2
  ctest --preset "$preset"
done
