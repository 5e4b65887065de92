#!/usr/bin/env bash
# The test command: installs dependencies, builds, runs the GoogleTest suite with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install_deps.sh
bash tools/build.sh
cd build
ctest --output-on-failure -j 2 --timeout 600
