#!/usr/bin/env bash
# Installs the Debian 12 packages cncd builds and tests with. Idempotent: packages already
# present are left alone and apt is not touched at all when nothing is missing.
set -euo pipefail

packages=(cmake ninja-build g++ pkg-config libmodbus-dev libgpiod-dev libspdlog-dev
          nlohmann-json3-dev libssl-dev libsystemd-dev libgtest-dev clang-14 libclang-rt-14-dev ccache
          libboost1.81-dev libargon2-dev libsqlite3-dev libjs-three
          libmosquitto-dev python3-prometheus-client python3-jsonschema)
for option in "$@"; do
  case "$option" in
    # LinuxCNC's standalone interpreter, used by the differential tests when present.
    --with-oracle) packages+=(linuxcnc-uspace) ;;
    # The browser the web page's tests drive.
    --with-browser) packages+=(chromium chromium-driver python3-selenium) ;;
    # The MQTT broker cncd-telemetry's tests publish through (its own, on a port of its own).
    --with-broker) packages+=(mosquitto) ;;
    *) echo "setup: unknown option '$option'" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done
if ((${#missing[@]} == 0)); then
  exit 0
fi

if ((EUID == 0)); then
  as_root=()
elif command -v sudo >/dev/null; then
  as_root=(sudo)
else
  echo "setup: need root or sudo to install: ${missing[*]}" >&2
  exit 1
fi
echo "setup: installing ${missing[*]}" >&2
"${as_root[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${as_root[@]}" apt-get install -y -qq --no-install-recommends \
  "${missing[@]}"
