#!/bin/sh
# Regenerates expected.canon (and expected.error) of golden cases with LinuxCNC's rs274.
# Usage: tests/golden/make_golden.sh [case ...]   (default: every case)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
rs274=${RS274:-/usr/bin/rs274}
[ "$#" -gt 0 ] || set -- $(cd "$here" && ls -d */ | tr -d /)
for name in "$@"; do
  dir="$here/$name"
  work=$(mktemp -d)
  args="-g"
  # Without a tool.tbl of its own, a case gets the committed copy of rs274's default table.
  table="$here/../interp/rs274_default.tbl"
  [ -f "$dir/tool.tbl" ] && table="$dir/tool.tbl"
  args="$args -t $table"
  [ -f "$dir/machine.ini" ] && args="$args -i $dir/machine.ini"
  if [ -f "$dir/params.var" ]; then cp "$dir/params.var" "$work/params.var"; args="$args -v $work/params.var"; fi
  (cd "$work" && "$rs274" $args "$dir/program.ngc" 2>"$work/stderr") |
    sed -n -E 's/^ *[0-9]+ N(\.\.\.\.\.|[0-9]+ *) //p' >"$dir/expected.canon"
  error=$(sed -n 2p "$work/stderr")
  if [ -n "$error" ]; then printf '%s\n' "$error" >"$dir/expected.error"; else rm -f "$dir/expected.error"; fi
  rm -rf "$work"
  echo "$name: $(wc -l <"$dir/expected.canon") lines${error:+, error: $error}"
done
