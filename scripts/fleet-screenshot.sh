#!/usr/bin/env bash
# Makes docs/fleet.png: the fleet page at 1280x720 as the fleet browser test sees it (three
# cncd on the simulated mill through their cncd-telemetry and one mosquitto: one running, one
# in estop, one offline), in Debian's headless Chromium.
# Usage: scripts/fleet-screenshot.sh [PRESET]   (default dev; the build is made if needed)
set -euo pipefail
cd "$(dirname "$0")/.."

preset=${1:-dev}
scripts/setup.sh --with-browser --with-broker
[[ -f build/$preset/CMakeCache.txt ]] || cmake --preset "$preset" >/dev/null
cmake --build "build/$preset" --target cncd cncd-telemetry cncd-fleet
CNCD_FLEET_SCREENSHOT=$PWD/docs/fleet.png PYTHONDONTWRITEBYTECODE=1 \
  /usr/bin/python3 tests/fleet/browser_fleet_test.py \
  --cncd "build/$preset/bin/cncd" --cncd-telemetry "build/$preset/bin/cncd-telemetry" \
  --cncd-fleet "build/$preset/bin/cncd-fleet" \
  --fleet-www "build/$preset/share/cncd/fleet-www" \
  --source-dir "$PWD" --out-dir "build/$preset/tests/fleet/browser"
echo "docs/fleet.png: $(stat -c %s docs/fleet.png) bytes"
