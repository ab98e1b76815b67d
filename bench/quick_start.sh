#!/usr/bin/env bash
# The README's Quick start, timed: a clean clone of this repository's HEAD into a temporary folder, then
# the three steps of scripts/run.sh one by one (setup.sh, the program's build, `tetra demo`), with ccache
# off so the build is a first build. Prints the wall time of each step and the total.
#
# The build figure is what the README quotes; run it on an idle machine (the load is printed first).
# setup.sh's time depends on what is installed: with every package present it checks them and installs nothing
# (the web application is setup.sh --web's, not the Quick start's).
#
# usage: bench/quick_start.sh [KEEP_DIR]     (KEEP_DIR: keep the clone there instead of deleting it)
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -n "${1:-}" ]; then
  work=$1
  mkdir -p "$work"
else
  work=$(mktemp -d /tmp/tetra-quick-start-XXXXXX)
  trap 'rm -rf "$work"' EXIT
fi
git clone -q . "$work/tetra"
cd "$work/tetra"
export CCACHE_DISABLE=1
echo "load: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores; commit $(git rev-parse --short HEAD)"

elapsed() { # STEP LOG COMMAND...: runs COMMAND, its output to LOG, and prints the step's wall time
  local step=$1 log=$2 t0 t1
  shift 2
  t0=$(date +%s.%N)
  if ! "$@" >"$log" 2>&1; then
    echo "$step failed; its output: $log" >&2
    tail -20 "$log" >&2
    exit 1
  fi
  t1=$(date +%s.%N)
  awk -v s="$step" -v a="$t0" -v b="$t1" 'BEGIN { d = b - a; printf "| %-28s | %3d min %4.1f s |\n", s, int(d / 60), d - 60 * int(d / 60) }'
  echo "$t0 $t1" >>"$work/times"
}

echo "| step                         | wall time     |"
echo "|------------------------------|---------------|"
elapsed "setup (packages)" "$work/setup.log" bash scripts/setup.sh
elapsed "build (tetra only, no ccache)" "$work/build.log" env TETRA_BUILD_TESTS=OFF bash scripts/build.sh --target tetra
elapsed "tetra demo" "$work/demo.log" ./build/tetra demo
awk 'NR == 1 { a = $1 } { b = $2 } END { d = b - a; printf "| %-28s | %3d min %4.1f s |\n", "total (bash scripts/run.sh)", int(d / 60), d - 60 * int(d / 60) }' "$work/times"
