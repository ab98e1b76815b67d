#!/usr/bin/env bash
# Runs one libFuzzer target from its seed corpus for a bounded time.
#   run_fuzzer.sh FUZZ_BUILD_DIR NAME SEED_CORPUS_DIR SECONDS [extra libFuzzer flags...]
# New inputs go to FUZZ_BUILD_DIR/work/NAME (the seed corpus in the repository is never modified);
# a crash is written to FUZZ_BUILD_DIR/artifacts/NAME-crash-* and the script exits non-zero with the
# command that reproduces it.
set -euo pipefail
out=${1:?fuzz build dir}
name=${2:?target name}
seeds=${3:?seed corpus dir}
seconds=${4:?seconds}
shift 4
bin="$out/fuzzers/fuzz_$name"
[ -x "$bin" ] || { echo "fuzz: $bin not built (run tests/fuzz/build_fuzzers.sh)" >&2; exit 1; }
work="$out/work/$name"
mkdir -p "$work" "$out/artifacts"
log="$out/work/$name.log"
# -timeout: one input taking > 10 s is a hang; -rss_limit_mb: a parser must not need 2 GB.
if "$bin" "$work" "$seeds" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix="$out/artifacts/$name-" -print_final_stats=1 "$@" >"$log" 2>&1; then
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  echo "fuzz_$name: ${runs:-?} inputs in ${seconds} s, 0 crashes (corpus $(ls "$work" | wc -l) + $(ls "$seeds" | wc -l) seeds)"
else
  grep -E "ERROR|SUMMARY|property|not one line|what\(\)|Test unit written" "$log" >&2 || tail -30 "$log" >&2
  artifact=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$log" | tail -1)
  echo "fuzz_$name: FAILED; reproduce with: $bin ${artifact:-<artifact>}  (full log: $log)" >&2
  exit 1
fi
