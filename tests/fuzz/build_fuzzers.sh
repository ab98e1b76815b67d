#!/usr/bin/env bash
# Configures and builds the libFuzzer targets in their own clang build directory.
#   build_fuzzers.sh SOURCE_DIR FUZZ_BUILD_DIR
# Run by ctest (test fuzz_build, the setup fixture of the fuzz_short_* tests) and by scripts/fuzz_long.sh.
# Fails loudly when clang or its libFuzzer runtime is missing: fuzzing is part of the test suite.
set -euo pipefail
src=${1:?source dir}
out=${2:?fuzz build dir}
cxx=${TETRA_FUZZ_CXX:-clang++}
cc=${TETRA_FUZZ_CC:-clang}

if ! command -v "$cxx" >/dev/null 2>&1; then
  echo "fuzz: $cxx not found; fuzzing needs Debian's clang: apt-get install -y clang libclang-rt-14-dev (scripts/setup.sh)" >&2
  exit 1
fi
probe=$(mktemp -d)
trap 'rm -rf "$probe"' EXIT
printf 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }\n' >"$probe/p.cpp"
if ! "$cxx" -fsanitize=fuzzer,address,undefined "$probe/p.cpp" -o "$probe/p" 2>"$probe/err"; then
  echo "fuzz: $cxx cannot link libFuzzer/ASan (install libclang-rt-14-dev): $(head -1 "$probe/err")" >&2
  exit 1
fi

cmake -S "$src" -B "$out" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" \
  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -gline-tables-only" -DCMAKE_C_FLAGS_DEBUG="-O1 -gline-tables-only" \
  -DTETRA_FUZZ=ON -DTETRA_BUILD_TESTS=OFF -DTETRA_BUILD_BENCH=OFF >"$out.configure.log" 2>&1 ||
  { cat "$out.configure.log" >&2; echo "fuzz: configure failed" >&2; exit 1; }
cmake --build "$out" -j "${TETRA_FUZZ_JOBS:-2}" --target tetra_fuzzers
