#!/usr/bin/env bash
# Sets up, builds and runs the demo: cncd on the simulated mill drills the G81 example.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release

bin=build/release/bin
example=${CNCD_DEMO_INI:-config/examples/sim_mm.ini}
program=${CNCD_DEMO_PROGRAM:-examples/g81_spindle.ngc}
rundir=$(mktemp -d)
sock=$rundir/cncd.sock
# The machine runs from the example INI as it is; its parameter, tool and position files go to
# a state directory of the demo's own (a machine's usual one is $XDG_STATE_HOME/cncd/<name>,
# docs/service.md), so that every demo starts from the example's shipped state and nothing is
# written into the source tree.
state=$rundir/state
ini=$example

"$bin/cncd" --ini "$ini" --state-dir "$state" --socket "$sock" 2>"$rundir/cncd.log" &
pid=$!
cleanup() {
  if kill -0 "$pid" 2>/dev/null; then
    kill -TERM "$pid"
    wait "$pid" || true
  fi
  rm -rf "$rundir"
}
trap cleanup EXIT

for _ in $(seq 100); do
  [[ -S $sock ]] && break
  if ! kill -0 "$pid" 2>/dev/null; then
    cat "$rundir/cncd.log" >&2
    echo "demo: cncd did not start" >&2
    exit 1
  fi
  sleep 0.1
done

ctl=("$bin/cncctl" --socket "$sock")
echo "== cncd running on $example"
"${ctl[@]}" reset
"${ctl[@]}" on
echo "== homing"
"${ctl[@]}" home
echo "== running $program"
"${ctl[@]}" run "$program"
echo "== final status"
"${ctl[@]}" status
echo "== cncd log"
cat "$rundir/cncd.log"
