#!/usr/bin/env bash
# Installs what tetra needs to build, test and plot, from Debian 12's packages.
# As root it runs apt-get; otherwise it prints the exact command to run.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libeigen3-dev libspdlog-dev libfmt-dev libyaml-cpp-dev libcli11-dev
  cyclonedds-dev cyclonedds-tools
  libgtest-dev libgmock-dev libbenchmark-dev
  libhdf5-dev                                 # HDF5 gyro logs
  gnuplot-nox
  clang libclang-rt-14-dev openssl iproute2   # reliability tests: fuzzers (clang), DDS Security PKI, netns
)

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
