#!/usr/bin/env bash
# Fuzzes the interpreter for SECONDS (default 600) with libFuzzer, ASan and UBSan, starting
# from tests/fuzz/corpus. Needs clang (scripts/setup.sh installs it). Crashing, hanging or
# leaking inputs are written to build/fuzz/artifacts/ and the script exits non-zero.
#   scripts/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
scripts/setup.sh
build=build/fuzz
clangxx=$(command -v clang++-14 || command -v clang++) || {
  echo "fuzz: clang++ not found" >&2
  exit 1
}
cmake -S tests/fuzz/standalone -B "$build" -G Ninja -DCMAKE_CXX_COMPILER="$clangxx" \
  -DCNCD_SOURCE_DIR="$PWD" >/dev/null
cmake --build "$build" --target cncd_interp_fuzz
exec tests/fuzz/run_fuzz.sh "$build/cncd_interp_fuzz" "$seconds" "$build" tests/fuzz/corpus
