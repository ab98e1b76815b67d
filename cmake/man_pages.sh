#!/usr/bin/env bash
# Man pages of tetra and of each command, from their --help texts (Debian's help2man):
#   man_pages.sh TETRA_BINARY VERSION OUT_DIR
# The commands are those `tetra help` lists, so a new command gets its page without editing this.
# Pages are written gzipped (tetra.1.gz, tetra-COMMAND.1.gz), as Debian installs them.
set -euo pipefail
tetra=${1:?usage: man_pages.sh TETRA_BINARY VERSION OUT_DIR}
version=${2:?version}
out=${3:?out dir}
command -v help2man >/dev/null || { echo "man_pages.sh: help2man not found (scripts/setup.sh installs it)" >&2; exit 1; }
mkdir -p "$out/wrappers"
rm -f "$out"/*.1.gz

page() {  # page PROGRAM NAME-LINE
  local program=$1 summary=$2 name
  name=$(basename "$program")
  help2man --no-info --no-discard-stderr --section=1 --version-string="$version" --name="$summary" \
    --output="$out/$name.1" "$program"
  # A command's help says "Usage: CMD [OPTIONS]"; the synopsis gets the program's name in front.
  [ "$name" = tetra ] || sed -i "s/^\.B ${name#tetra-}\$/.B tetra ${name#tetra-}/" "$out/$name.1"
  gzip -9nf "$out/$name.1"
}

page "$tetra" "calibration, noise, simulation and fault-tolerant fusion for redundant gyro packages"
# `tetra help` lists "  NAME       summary" under "commands:"; `help` itself has no page of its own.
"$tetra" help | sed -n 's/^  \([a-z][a-z-]*\) \+\(.*\)$/\1\t\2/p' | while IFS=$'\t' read -r cmd summary; do
  [ "$cmd" = help ] && continue
  wrapper="$out/wrappers/tetra-$cmd"
  printf '#!/bin/sh\nexec "%s" %s "$@"\n' "$tetra" "$cmd" >"$wrapper"
  chmod +x "$wrapper"
  page "$wrapper" "$summary"
done
touch "$out/stamp"
