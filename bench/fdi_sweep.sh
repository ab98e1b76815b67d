#!/usr/bin/env bash
# Fault-free sweep of the fusion pipeline (≥ 1,000 one-hour orbits per N = 4, 5, 6 with the simulator's default
# unit, in process on every core) and detection delays of the documented faults against the CUSUM theory
# (docs/fdi.md, "Detection"). Prints the load average beside the run time.
# Usage: bench/fdi_sweep.sh [BUILD_DIR] [HOURS] [fdi_sweep options...]   (defaults: build, 1000), e.g.
#   bench/fdi_sweep.sh build 1000 --quantization 6e-5     (every gyro quantized, N = 4, 5, 6)
#   bench/fdi_sweep.sh build 1000 --unit examples/sim/allan_unit.yaml
# Build: scripts/build.sh --target fdi_sweep
set -euo pipefail
build="${1:-build}"
hours="${2:-1000}"
echo "cores: $(nproc); load before: $(cut -d' ' -f1-3 /proc/loadavg)"
start=$(date +%s.%N)
"$build/bench/fdi_sweep" --hours "$hours" --jobs "$(nproc)" --delay-seeds 10 "${@:3}"
end=$(date +%s.%N)
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "run time: $(echo "$end - $start" | bc) s wall"
