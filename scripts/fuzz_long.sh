#!/usr/bin/env bash
# Long fuzzing run of every libFuzzer target (docs/reliability.md).
#   scripts/fuzz_long.sh [SECONDS_PER_TARGET=300] [BUILD_DIR=build] [TARGET...]
# Builds the fuzzers (clang, build/fuzz) if needed, runs each target from its seed corpus plus what
# earlier runs found (build/fuzz/work/<name>), and prints executions and crashes per target.
# Exit status 1 if any target crashed; the crashing inputs are in build/fuzz/artifacts/.
set -uo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-300}
build=${2:-build}
shift $(($# > 2 ? 2 : $#))
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  names=(csv gyro_log gyro_log_h5 turntable_log calibration scenario campaign_spec fault_spec calibrate allan tau_spec pipeline
         pipeline_config fusion_config security_profile)
fi
bash tests/fuzz/build_fuzzers.sh "$PWD" "$PWD/$build/fuzz" >/dev/null || exit 1
failed=0
for name in "${names[@]}"; do
  [ -x "$build/fuzz/fuzzers/fuzz_$name" ] || { echo "fuzz_$name: not built (skipped)"; continue; }
  if ! bash tests/fuzz/run_fuzzer.sh "$PWD/$build/fuzz" "$name" "tests/fuzz/corpus/$name" "$seconds"; then
    failed=1
  fi
done
exit $failed
