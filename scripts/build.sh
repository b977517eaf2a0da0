#!/usr/bin/env bash
# Configures and builds Drover into build/ (executables in build/bin/). -j2: machines are small.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE="${DROVER_BUILD_TYPE:-RelWithDebInfo}" "$@" >/dev/null
cmake --build build -j"${DROVER_JOBS:-2}"
