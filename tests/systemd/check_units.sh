#!/usr/bin/env bash
# The unit files parse, and each service's exposure stays at 2.0 or lower.
set -euo pipefail
units=${1:?usage: check_units.sh SYSTEMD_DIR}
if ! command -v systemd-analyze >/dev/null; then
  echo "systemd-analyze not installed: skipped"
  exit 77
fi
for service in cncd.service cncd-web.service cncd-telemetry.service cncd-fleet.service; do
  report=$(systemd-analyze security --offline=true --no-pager "$units/$service")
  score=$(printf '%s\n' "$report" | sed -n "s/.*Overall exposure level for $service: \\([0-9.]*\\).*/\\1/p")
  echo "$service exposure: ${score:-unknown}"
  [[ -n $score ]] || { printf '%s\n' "$report"; exit 1; }
  awk -v s="$score" 'BEGIN { exit !(s <= 2.0) }' || { printf '%s\n' "$report" | grep '✗'; exit 1; }
done
grep -q '^ListenStream=/run/cncd/cncd.sock$' "$units/cncd.socket"
grep -q '^Type=notify$' "$units/cncd.service"
# cncd-web comes after cncd's socket, which it needs.
grep -q '^Requires=cncd.socket$' "$units/cncd-web.service"
grep -q '^After=cncd.socket' "$units/cncd-web.service"
grep -q '^Requires=cncd.socket$' "$units/cncd-telemetry.service"
# cncd-fleet reads the broker only: it has nothing to do with cncd's socket.
! grep -qF 'cncd.socket' "$units/cncd-fleet.service"
