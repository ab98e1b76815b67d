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
# C++ (Debian 12 has no Cyclone C++ binding): the generated C types compiled by cc, the program by c++.
cc -O2 -Wall -Wextra -Werror -c -I"$out/gen" "$out/gen/tetra.c" -o "$out/gen/tetra.o"
c++ -std=c++17 -O2 -Wall -Wextra -Werror -I"$out/gen" "$src/examples/dds/cpp_subscriber.cpp" "$out/gen/tetra.o" \
  -lddsc -o "$out/cpp_subscriber"
echo "built $out/attitude_subscriber, $out/star_tracker and $out/cpp_subscriber"
