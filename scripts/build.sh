#!/usr/bin/env bash
# Configures and builds Drover into build/ (executables in build/bin/). -j2: machines are small.
set -euo pipefail
cd "$(dirname "$0")/.."
# ccache (installed by install-deps.sh) makes rebuilds and fresh clones on the same machine
# cheap; paths are taken relative to the clone, so two clones share the cache.
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE="${DROVER_BUILD_TYPE:-RelWithDebInfo}" "${launcher[@]}" "$@" >/dev/null
cmake --build build -j"${DROVER_JOBS:-2}"
