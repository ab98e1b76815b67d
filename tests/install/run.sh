#!/usr/bin/env bash
# The install test (ctest install_consumer): installs the build tree into a temporary prefix, then
#  1. the installed program runs, its man pages (one per command), bash completion and web application
#     are in place, and `tetra ground` finds the web application beside itself;
#  2. tests/install (find_package(tetra), tetra::core/fdi/sim) configures, builds and runs against it;
#  3. a program built with `pkg-config --cflags --libs tetra` alone compiles, links and runs;
#  4. when the build has the Python package (TETRA_PYTHON), `import tetra` works from the prefix's
#     lib/python3/dist-packages and runs the pipeline there.
#   run.sh SOURCE_DIR BUILD_DIR WORK_DIR [PYTHON]    (PYTHON: the interpreter the module was built for)
set -euo pipefail
src=${1:?usage: run.sh SOURCE_DIR BUILD_DIR WORK_DIR}
build=${2:?build dir}
work=${3:?work dir}
python=${4:-/usr/bin/python3}
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
# One man page per command `tetra help` lists, and tetra.1 (docs/install.md gives the count).
commands=$("$prefix/bin/tetra" help | sed -n '/^commands:/,$p' | awk '/^  [a-z]/ && $1 != "help" {print $1}')
for c in $commands; do
  [ -n "$(find "$prefix" -path "*/man1/tetra-$c.1.gz")" ] || { echo "install: no man page for $c" >&2; exit 1; }
done
pages=$(find "$prefix" -path "*/man1/tetra*.1.gz" | wc -l)
grep -q "its $pages man pages" "$src/docs/install.md" ||
  { echo "install: $pages man pages installed; docs/install.md says otherwise" >&2; exit 1; }
# The ground station's web application, found by the installed program beside itself.
[ -f "$prefix/share/tetra/web/index.html" ] || { echo "install: no web application" >&2; exit 1; }
"$prefix/bin/tetra" ground --help | grep -q -- "--web TEXT=$prefix/share/tetra/web" ||
  { echo "install: tetra ground does not default to the installed web application" >&2; exit 1; }

cmake -S "$src/tests/install" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
  >"$work/consumer-configure.log"
cmake --build "$work/consumer" >"$work/consumer-build.log"
"$work/consumer/tetra_consumer"

pc_dir=$(dirname "$(find "$prefix" -name tetra.pc | head -1)")
flags=$(PKG_CONFIG_PATH=$pc_dir pkg-config --cflags --libs tetra)
# shellcheck disable=SC2086  # the flags are words
c++ -std=c++20 -O1 "$src/tests/install/pkgconfig.cpp" -o "$work/pkgconfig_consumer" $flags
"$work/pkgconfig_consumer"
if compgen -G "$build/python/tetra/_tetra*.so" >/dev/null; then
  site=$prefix/lib/python3/dist-packages
  [ -f "$site/tetra/__init__.pyi" ] || { echo "install: no type stubs in $site/tetra" >&2; exit 1; }
  (cd "$work" && PYTHONPATH=$site "$python" -c '
import sys, numpy as np, tetra
assert tetra.__file__.startswith(sys.argv[1]), tetra.__file__
cal = tetra.Calibration.seed_unit()
run = tetra.Pipeline(cal).run(np.arange(10) * 0.1, np.tile(cal.bias_V, (10, 1)))
assert len(run) == 10
' "$site") || { echo "install: import tetra from $site failed" >&2; exit 1; }
fi
echo "install: PASS ($prefix)"
