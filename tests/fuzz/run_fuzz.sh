#!/usr/bin/env bash
# Runs a fuzz target for SECONDS over its seed corpus (with a libFuzzer dictionary when given);
# fails on any crash, hang (an input over 10 s), leak or use of more than 2 GB. New inputs go
# to WORK/corpus, findings to WORK/artifacts; the seed corpus is only read.
#   run_fuzz.sh FUZZER SECONDS WORK SEED_CORPUS [DICTIONARY]
set -euo pipefail
fuzzer=$1 seconds=$2 work=$3 seeds=$4
dict=()
if (($# > 4)); then dict=(-dict="$5"); fi
mkdir -p "$work/corpus" "$work/artifacts"
exec "$fuzzer" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
  -print_final_stats=1 "${dict[@]}" -artifact_prefix="$work/artifacts/" "$work/corpus" "$seeds"
