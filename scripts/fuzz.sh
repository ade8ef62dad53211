#!/usr/bin/env bash
# Fuzzes with libFuzzer, ASan and UBSan for SECONDS each (default 600): the interpreter
# (seeds in tests/fuzz/corpus), the control protocol's request path (tests/fuzz/rpc_corpus), or
# both in turn. Needs clang (scripts/setup.sh installs it). Crashing, hanging or leaking inputs
# are written to build/fuzz/out/TARGET/artifacts/ and the script exits non-zero.
#   scripts/fuzz.sh [SECONDS] [interp|rpc|all]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
case ${2:-all} in
  interp | rpc) targets=("$2") ;;
  all) targets=(interp rpc) ;;
  *)
    echo "usage: scripts/fuzz.sh [SECONDS] [interp|rpc|all]" >&2
    exit 64
    ;;
esac
scripts/setup.sh
build=build/fuzz
clangxx=$(command -v clang++-14 || command -v clang++) || {
  echo "fuzz: clang++ not found" >&2
  exit 1
}
declare -A seeds=([interp]=tests/fuzz/corpus [rpc]=tests/fuzz/rpc_corpus)
declare -A dicts=([interp]="" [rpc]=tests/fuzz/rpc.dict)
cmake -S tests/fuzz/standalone -B "$build" -G Ninja -DCMAKE_CXX_COMPILER="$clangxx" \
  -DCNCD_SOURCE_DIR="$PWD" >/dev/null
binaries=()
for target in "${targets[@]}"; do binaries+=("cncd_${target}_fuzz"); done
cmake --build "$build" --target "${binaries[@]}"
failed=()
for target in "${targets[@]}"; do
  echo "fuzz: $target for $seconds s" >&2
  tests/fuzz/run_fuzz.sh "$build/cncd_${target}_fuzz" "$seconds" "$build/out/$target" \
    "${seeds[$target]}" ${dicts[$target]} || failed+=("$target")
done
if ((${#failed[@]} > 0)); then
  echo "fuzz: findings in ${failed[*]}: see $build/out/*/artifacts/" >&2
  exit 1
fi
