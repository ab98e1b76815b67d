#!/usr/bin/env bash
# Installs what tetra needs from Debian 12's packages.
#   setup.sh          what building and running the program needs (scripts/run.sh)
#   setup.sh --test   that and what the test suite needs: GoogleTest, Google Benchmark, gnuplot (allan
#                     --plot), clang (fuzzers), openssl (DDS Security PKI), iproute2 (netns tests)
# As root it runs apt-get; otherwise it prints the exact command to run.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libeigen3-dev libspdlog-dev libfmt-dev libyaml-cpp-dev libcli11-dev
  cyclonedds-dev cyclonedds-tools
  help2man                                    # man pages from the --help texts (cmake --install)
)
if [ "${1:-}" = "--test" ]; then
  packages+=(
    libgtest-dev libgmock-dev libbenchmark-dev
    gnuplot-nox
    clang libclang-rt-14-dev openssl iproute2   # reliability tests: fuzzers (clang), DDS Security PKI, netns
  )
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

cmd="apt-get install -y --no-install-recommends ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "setup: missing packages: ${missing[*]}" >&2
  echo "setup: run as root:  apt-get update && $cmd" >&2
  exit 1
fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
