#!/usr/bin/env bash
# cmake --install puts binaries, units, sysusers/tmpfiles snippets, example machines and the
# documentation in their FHS places, and the installed unit starts the installed daemon.
set -euo pipefail
build=${1:?usage: check_install.sh BUILD_DIR}
root=$(mktemp -d)
trap 'rm -rf "$root"' EXIT
cmake --install "$build" --prefix "$root/usr" >/dev/null
missing=0
for file in usr/sbin/cncd usr/bin/cncctl usr/bin/cncd-check usr/bin/cncd-drive-sim usr/bin/cncd-web usr/bin/cncd-telemetry usr/bin/cncd-fleet \
  usr/lib/systemd/system/cncd.service usr/lib/systemd/system/cncd.socket \
  usr/lib/systemd/system/cncd-web.service usr/lib/sysusers.d/cncd-web.conf \
  usr/lib/systemd/system/cncd-telemetry.service usr/lib/sysusers.d/cncd-telemetry.conf \
  usr/lib/systemd/system/cncd-fleet.service usr/share/cncd/fleet-www/index.html \
  usr/lib/sysusers.d/cncd.conf usr/lib/tmpfiles.d/cncd.conf \
  usr/share/cncd/examples/sim_mm.ini usr/share/cncd/examples/g81_example1.ngc \
  usr/share/doc/cncd/README.md usr/share/doc/cncd/protocol.md usr/share/doc/cncd/service.md; do
  if [[ ! -e $root/$file ]]; then
    echo "missing: /$file"
    missing=1
  fi
done
for service in cncd.service cncd-web.service cncd-telemetry.service cncd-fleet.service; do
  exec_start=$(sed -n 's/^ExecStart=\([^ ]*\).*/\1/p' "$root/usr/lib/systemd/system/$service")
  [[ -x $root$exec_start ]] || { echo "$service: ExecStart=$exec_start is not installed"; missing=1; }
done
"$root/usr/sbin/cncd" --check-config "$root/usr/share/cncd/examples/sim_mm.ini" >/dev/null ||
  { echo "the installed cncd cannot check the installed example"; missing=1; }
[[ $missing == 0 ]] && echo "installed in $root/usr: ok"
exit $missing
