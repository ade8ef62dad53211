#!/usr/bin/env bash
# The unit files parse, and the service's exposure stays at 2.0 or lower.
set -euo pipefail
units=${1:?usage: check_units.sh SYSTEMD_DIR}
if ! command -v systemd-analyze >/dev/null; then
  echo "systemd-analyze not installed: skipped"
  exit 77
fi
report=$(systemd-analyze security --offline=true --no-pager "$units/cncd.service")
score=$(printf '%s\n' "$report" | sed -n 's/.*Overall exposure level for cncd.service: \([0-9.]*\).*/\1/p')
echo "exposure: ${score:-unknown}"
[[ -n $score ]] || { printf '%s\n' "$report"; exit 1; }
awk -v s="$score" 'BEGIN { exit !(s <= 2.0) }' || { printf '%s\n' "$report" | grep '✗'; exit 1; }
grep -q '^ListenStream=/run/cncd/cncd.sock$' "$units/cncd.socket"
grep -q '^Type=notify$' "$units/cncd.service"
