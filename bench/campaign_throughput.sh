#!/usr/bin/env bash
# Campaign throughput: examples/campaign.yaml (520 closed-loop runs of 10 min, pipeline in process) with
# --jobs J, for each tetra program given, ROUNDS times interleaved (a shared machine's load moves): wall
# runs/s, and CPU seconds per run (user + system of the campaign and its workers, the figure a loaded
# machine disturbs least). Comparing two programs shows what a runner costs per run.
# Usage: bench/campaign_throughput.sh [-j J] [-r ROUNDS] TETRA...   (default: -j 2 -r 2 build/tetra)
set -euo pipefail
jobs=2 rounds=2
while getopts j:r: o; do case $o in j) jobs=$OPTARG ;; r) rounds=$OPTARG ;; *) exit 2 ;; esac; done
shift $((OPTIND - 1))
[ $# -gt 0 ] || set -- build/tetra
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "cores: $(nproc), --jobs $jobs; load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for ((r = 1; r <= rounds; ++r)); do
  for tetra in "$@"; do
    rm -rf "$out/c"
    /usr/bin/time -f "%e %U %S" -o "$out/time" "$tetra" campaign examples/campaign.yaml --out "$out/c" \
      --jobs "$jobs" --no-report 2>/dev/null
    read -r wall user sys <"$out/time"
    runs=$(($(wc -l <"$out/c/runs.csv") - 1))
    awk -v t="$tetra" -v n="$runs" -v w="$wall" -v u="$user" -v s="$sys" -v l="$(cut -d' ' -f1 /proc/loadavg)" \
      'BEGIN { printf "%s: %d runs in %.1f s wall = %.1f runs/s; CPU %.1f ms/run; load %s\n", t, n, w, n / w, 1000 * (u + s) / n, l }'
  done
done
