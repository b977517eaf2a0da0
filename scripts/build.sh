#!/usr/bin/env bash
# Configures and builds Drover into build/ (executables in build/bin/). -j2: machines are small.
# DROVER_BUILD_DIR builds elsewhere, DROVER_BUILD_TARGETS (space-separated) builds only those
# (run-sanitized-tests.sh uses both); extra arguments go to CMake.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${DROVER_BUILD_DIR:-build}"
# ccache (installed by install-deps.sh) makes rebuilds and fresh clones on the same machine
# cheap; paths are taken relative to the clone, so two clones share the cache.
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
fi
targets=()
if [[ -n "${DROVER_BUILD_TARGETS:-}" ]]; then
  read -r -a names <<<"$DROVER_BUILD_TARGETS"
  targets=(--target "${names[@]}")
fi
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE="${DROVER_BUILD_TYPE:-RelWithDebInfo}" "${launcher[@]}" "$@" >/dev/null
cmake --build "$build_dir" -j"${DROVER_JOBS:-2}" "${targets[@]}"
