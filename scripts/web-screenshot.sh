#!/usr/bin/env bash
# Makes docs/web-dashboard.png: the page at 1024x600 as the browser operator test leaves it (the
# G81 example open and run on the simulated mill), in Debian's headless Chromium.
# Usage: scripts/web-screenshot.sh [PRESET]   (default dev; the build is made if needed)
set -euo pipefail
cd "$(dirname "$0")/.."

preset=${1:-dev}
scripts/setup.sh --with-browser
[[ -f build/$preset/CMakeCache.txt ]] || cmake --preset "$preset" >/dev/null
cmake --build "build/$preset" --target cncd cncd-web
CNCD_WEB_SCREENSHOT=$PWD/docs/web-dashboard.png PYTHONDONTWRITEBYTECODE=1 \
  /usr/bin/python3 tests/web/browser_operator_test.py \
  --cncd "build/$preset/bin/cncd" --cncd-web "build/$preset/bin/cncd-web" \
  --source-dir "$PWD" --out-dir "build/$preset/tests/web/browser"
echo "docs/web-dashboard.png: $(stat -c %s docs/web-dashboard.png) bytes"
