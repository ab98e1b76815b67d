#!/usr/bin/env bash
# Installs what is missing (test packages included), builds everything, and runs every test through ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --test
bash scripts/build.sh
cd build
ctest --output-on-failure -j "$(nproc)" --timeout 600
