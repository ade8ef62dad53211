#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite through ctest.
# Arguments name CMake presets to build and test (default: dev, a debug build with warnings as
# errors); e.g. `scripts/test.sh asan-ubsan tsan` runs the suite under the sanitizers.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
presets=("$@")
((${#presets[@]} > 0)) || presets=(dev)
for preset in "${presets[@]}"; do
  echo "== $preset: build" >&2
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset"
  echo "== $preset: test" >&2
  ctest --preset "$preset"
done
