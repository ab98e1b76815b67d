#!/usr/bin/env bash
# A unit noisier than its noise: section, replayed on the stated figures (docs/fdi_validation.md, "Beyond the
# envelope: a unit noisier than its noise: section"): the seed paper's unit with its white noise and bias
# instability FACTOR times the stated, SEEDS two-hour runs of slews at 10 Hz without a reference, each
# replayed on the unit's stated calibration. Prints per seed the events, the gyros excluded and the NEES
# (expectation 3) with the fraction of x errors within 3 sigma.
# WHITE, when given, is the white noise's factor instead (1: a unit noisier in its bias instability alone).
# Usage: bench/noisy_unit.sh [BUILD_DIR] [FACTOR] [SEEDS] [WHITE]   (defaults: build, 3, 4, FACTOR; about 1 min)
set -euo pipefail
build="$(realpath "${1:-build}")"
factor="${2:-3}"
seeds="${3:-4}"
white="${4:-$factor}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
echo "cores: $(nproc); load before: $(cut -d' ' -f1-3 /proc/loadavg); white noise x $white, bias instability x $factor"
"$build/tetra" sim --write-unit "$out/stated.yaml" >/dev/null 2>&1
python3 - "$out/stated.yaml" "$out/true.yaml" "$factor" "$white" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
factor = {"bias_instability_dps": float(sys.argv[3]), "arw_dps_rtHz": float(sys.argv[4])}
scale = lambda m: f"{m.group(1)}: {float(m.group(2)) * factor[m.group(1)]:g}"
open(sys.argv[2], "w").write(re.sub(r"(arw_dps_rtHz|bias_instability_dps): ([0-9.eE+-]+)", scale, text))
PY
for s in $(seq 1 "$seeds"); do
  "$build/tetra" sim slews --unit "$out/true.yaml" --minutes 120 --seed "$s" -o "$out/log.h5" \
    --truth "$out/truth.csv" >/dev/null 2>&1
  summary=$("$build/tetra" replay "$out/log.h5" --calibration "$out/stated.yaml" --attitude "$out/att.csv" \
    --events "$out/ev.jsonl" 2>&1 | grep -E "events:|final mode" | sed 's/^ *//' | tr '\n' ';')
  score=$("$build/tetra" score "$out/att.csv" "$out/truth.csv" 2>&1 |
    grep -E "NEES|within 1/2/3 sigma, x" | sed 's/^ *//; s/ (Gaussian.*//; s/(expectation 3): //' | tr '\n' ';')
  echo "seed $s: $summary $score"
done
