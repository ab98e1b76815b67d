#!/usr/bin/env bash
# The install test (ctest install_consumer): installs the build tree into a temporary prefix, then
#  1. the installed program runs, its man pages and bash completion are in place;
#  2. tests/install (find_package(tetra), tetra::core/fdi/sim) configures, builds and runs against it;
#  3. a program built with `pkg-config --cflags --libs tetra` alone compiles, links and runs.
#   run.sh SOURCE_DIR BUILD_DIR WORK_DIR
set -euo pipefail
src=${1:?usage: run.sh SOURCE_DIR BUILD_DIR WORK_DIR}
build=${2:?build dir}
work=${3:?work dir}
rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" >"$work/install.log"
"$prefix/bin/tetra" help | grep -q calibrate
for page in tetra tetra-calibrate tetra-allan tetra-sim tetra-replay tetra-fusion tetra-demo; do
  f=$(find "$prefix" -path "*/man1/$page.1.gz" | head -1)
  [ -n "$f" ] || { echo "install: man page $page.1.gz missing" >&2; exit 1; }
  zcat "$f" | grep -q '^\.SH' || { echo "install: $f is not a man page" >&2; exit 1; }
done
[ -f "$prefix/share/bash-completion/completions/tetra" ] || { echo "install: no bash completion" >&2; exit 1; }
[ -f "$prefix/share/tetra/idl/tetra.idl" ] || { echo "install: no IDL" >&2; exit 1; }

cmake -S "$src/tests/install" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
  >"$work/consumer-configure.log"
cmake --build "$work/consumer" >"$work/consumer-build.log"
"$work/consumer/tetra_consumer"

pc_dir=$(dirname "$(find "$prefix" -name tetra.pc | head -1)")
flags=$(PKG_CONFIG_PATH=$pc_dir pkg-config --cflags --libs tetra)
# shellcheck disable=SC2086  # the flags are words
c++ -std=c++20 -O1 "$src/tests/install/pkgconfig.cpp" -o "$work/pkgconfig_consumer" $flags
"$work/pkgconfig_consumer"
echo "install: PASS ($prefix)"
