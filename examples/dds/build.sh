#!/bin/sh
# Builds the C examples from idl/tetra.idl with nothing but Cyclone DDS's idlc and libddsc (Debian 12:
# apt-get install cyclonedds-dev cyclonedds-tools), as docs/dds.md "Your own subscriber" writes it:
#   sh examples/dds/build.sh [OUT]      (OUT default: build/examples-dds; run from anywhere)
set -eu
src=$(cd "$(dirname "$0")/../.." && pwd)
out=${1:-$src/build/examples-dds}
mkdir -p "$out/gen"
idlc -Wno-implicit-extensibility -o "$out/gen" "$src/idl/tetra.idl"  # writes gen/tetra.c and gen/tetra.h
for name in attitude_subscriber star_tracker; do
  cc -O2 -Wall -Wextra -Werror -I"$out/gen" "$src/examples/dds/$name.c" "$out/gen/tetra.c" -lddsc -lm \
    -o "$out/$name"
done
echo "built $out/attitude_subscriber and $out/star_tracker"
