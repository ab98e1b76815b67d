#!/usr/bin/env bash
# Installs what tetra needs from Debian 12's packages and, when asked for, the ground station's web
# application (web/: Open MCT, pinned by web/package-lock.json) with `npm ci`.
#   setup.sh          what building and running the program needs (scripts/run.sh: tetra demo needs no web
#                     application, so neither Node.js nor npm ci)
#   setup.sh --web    that and the web application of `tetra ground` (Node.js and npm, then npm ci in web/)
#   setup.sh --test   that, the web application, and what the test suite needs: GoogleTest, Google Benchmark, gnuplot (allan
#                     --plot), clang (fuzzers), openssl (DDS Security PKI), iproute2 (netns tests), chromium
#                     and selenium (the ground station's browser test), slurm-wlm and munge (the
#                     campaign's Slurm test), pybind11 and Python's numpy, pandas, pytest and matplotlib
#                     (the Python package, its tests and example), venv, build and mypy (pip install .
#                     in a fresh venv, the wheel, the stub check)
# As root it runs apt-get; otherwise it prints the exact command to run.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libspdlog-dev libfmt-dev libyaml-cpp-dev libcli11-dev
  cyclonedds-dev cyclonedds-tools
  libcpp-httplib-dev nlohmann-json3-dev       # tetra ground: HTTP client of the tests, JSON
  libsodium-dev libssl-dev                    # tetra ground: argon2id password hashes, TLS
  libboost-dev                                # tetra ground: its HTTP server (Boost.Beast on Asio, headers only)
  libhdf5-dev                                 # HDF5 gyro logs
  help2man                                    # man pages from the --help texts (cmake --install)
)
web=false
if [ "${1:-}" = "--web" ] || [ "${1:-}" = "--test" ]; then web=true; fi
# Node.js and npm for web/ (Debian's nodejs and npm, unless a node with npm is already installed).
if $web && ! command -v npm >/dev/null; then packages+=(nodejs npm); fi
if [ "${1:-}" = "--test" ]; then
  packages+=(
    libgtest-dev libgmock-dev libbenchmark-dev
    gnuplot-nox
    clang libclang-rt-14-dev openssl iproute2   # reliability tests: fuzzers (clang), DDS Security PKI, netns
    chromium chromium-driver python3-selenium    # the ground station's browser test
    slurm-wlm munge                              # the campaign over a single-node Slurm cluster
    pybind11-dev python3-dev                     # the Python package tetra (docs/python.md)
    python3-numpy python3-pandas python3-pytest python3-matplotlib  # its tests and notebook example
    python3-venv python3-build python3-mypy      # pip install . in a fresh venv, python3 -m build, stub check
    python3-tqdm                                 # progress bars of the long calls
  )
fi

# The web application's packages: `npm ci` installs exactly the versions of web/package-lock.json.
web_packages() {
  local want have
  want=$(node -p "require('./web/package-lock.json').packages['node_modules/openmct'].version")
  have=$(node -p "try { require('./web/node_modules/openmct/package.json').version } catch (e) { '' }")
  if [ "$want" = "$have" ] && [ -f web/node_modules/openmct/dist/openmct.js ]; then
    echo "setup: web/node_modules up to date"
    return 0
  fi
  echo "setup: npm ci in web/"
  (cd web && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error)
}

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  if $web; then web_packages; fi
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
if $web; then web_packages; fi
