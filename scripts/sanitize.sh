#!/usr/bin/env bash
# ASan + UBSan build of the whole test suite in its own build directory, then the suite under it.
#   scripts/sanitize.sh [ctest args...]     e.g. scripts/sanitize.sh -R test_sim
# Every target (libraries, tetra, tests) is compiled with -fsanitize=address,undefined
# -fno-sanitize-recover=all (root option TETRA_SANITIZE): any report fails the test that triggered it.
# The fuzz_* tests are left out here: the fuzzers already run under ASan+UBSan in their own build.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${TETRA_SANITIZE_DIR:-build-asan}
jobs=${TETRA_JOBS:-$(nproc)}
cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" -DCMAKE_C_FLAGS_DEBUG="-O1 -g" \
  -DTETRA_SANITIZE=address,undefined -DTETRA_BUILD_BENCH=OFF >/dev/null
cmake --build "$dir" -j "$jobs"
# halt_on_error/abort: a report is a failure, never a warning in a log nobody reads.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
if [ -f scripts/lsan.supp ]; then export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/scripts/lsan.supp:print_suppressions=0}; fi
cd "$dir"
ctest --output-on-failure -j "$jobs" --timeout 900 -E '^fuzz_' "$@"
