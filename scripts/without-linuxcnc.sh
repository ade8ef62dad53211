#!/usr/bin/env bash
# Runs COMMAND as on a machine without LinuxCNC: in a private mount namespace where every file
# of the installed linuxcnc* packages (rs274, its sample programs and configs, its libraries)
# is hidden. Directories named after LinuxCNC are covered by an empty tmpfs; its files in
# shared directories (/usr/bin, /usr/lib ...) by an overlay that whites them out. Nothing
# outside the namespace changes. Without LinuxCNC installed, COMMAND simply runs.
#   scripts/without-linuxcnc.sh COMMAND [ARG ...]
set -euo pipefail
(($# > 0)) || {
  echo "usage: $0 COMMAND [ARG ...]" >&2
  exit 64
}

if [[ "${CNCD_LINUXCNC_HIDDEN:-}" != 1 ]]; then
  mapfile -t packages < <(dpkg-query -W -f='${db:Status-Abbrev} ${Package}\n' 'linuxcnc*' \
    2>/dev/null | awk '$1 ~ /^.i/ {print $2}')
  if ((${#packages[@]} == 0)); then
    exec "$@"
  fi
  if ((EUID != 0)); then
    echo "without-linuxcnc: hiding ${packages[*]} needs root (a private mount namespace)" >&2
    exit 77
  fi
  export CNCD_LINUXCNC_HIDDEN=1
  exec unshare --mount --propagation private "$0" "$@"
fi

# Inside the namespace: one overlay on each top-level directory holding LinuxCNC files, whose
# upper layer whites out the outermost directory named after LinuxCNC (nothing of anyone
# else's is in it) or else the file itself.
scratch=$(mktemp -d /tmp/without-linuxcnc.XXXXXX)
mount -t tmpfs tmpfs "$scratch"
mapfile -t packages < <(dpkg-query -W -f='${db:Status-Abbrev} ${Package}\n' 'linuxcnc*' |
  awk '$1 ~ /^.i/ {print $2}')
mapfile -t hidden < <(dpkg -L "${packages[@]}" |
  perl -pe 's#^/(lib|lib64|bin|sbin)/#/usr/$1/#; s#^(.*?/[^/]*linuxcnc[^/]*)/.*#$1#' | sort -u)
declare -A roots=() made=()
for path in "${hidden[@]}"; do
  [[ $path == /*/* ]] || continue
  [[ -e $path || -L $path ]] || continue
  [[ -d $path && ! $path =~ linuxcnc[^/]*$ ]] && continue
  root=${path#/}
  root=/${root%%/*}
  rel=${path#"$root"}
  roots[$root]=1
  if [[ -z ${made[$root${rel%/*}]:-} ]]; then
    mkdir -p "$scratch$root/upper${rel%/*}"
    made[$root${rel%/*}]=1
  fi
  mknod "$scratch$root/upper$rel" c 0 0
done
for root in "${!roots[@]}"; do
  mkdir -p "$scratch$root/work"
  mount -t overlay overlay \
    -o "lowerdir=$root,upperdir=$scratch$root/upper,workdir=$scratch$root/work" "$root"
done

if command -v rs274 >/dev/null || [[ -e /usr/share/doc/linuxcnc/examples ]]; then
  echo "without-linuxcnc: LinuxCNC is still visible" >&2
  exit 70
fi
echo "without-linuxcnc: ${packages[*]} hidden" >&2
exec "$@"
