#!/usr/bin/env bash
# Runs the interpreter fuzz target for SECONDS over the seed corpus; fails on any crash, hang
# (an input over 10 s), leak or use of more than 2 GB. Findings land in WORK/artifacts.
#   run_fuzz.sh FUZZER SECONDS WORK SEED_CORPUS
set -euo pipefail
fuzzer=$1 seconds=$2 work=$3 seeds=$4
mkdir -p "$work/corpus" "$work/artifacts"
exec "$fuzzer" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
  -print_final_stats=1 -artifact_prefix="$work/artifacts/" "$work/corpus" "$seeds"
