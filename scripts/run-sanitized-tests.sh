#!/usr/bin/env bash
# The pure libraries' unit tests (topology, carp: no DDS, no processes) built with
# AddressSanitizer and UBSan into build-sanitize/, and run. Those libraries keep raw pointers
# into arenas and timelines between calls (docs/carp.md, docs/timelines.md), where a bug
# would corrupt memory silently; any report fails the run. Called by run-tests.sh after the
# main suite; the build directory is separate, so `build/` keeps its optimised binaries.
set -euo pipefail
cd "$(dirname "$0")/.."
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
fi
tests=(test_topology test_timeline test_carp)
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDROVER_SANITIZE=ON \
  "${launcher[@]}" >/dev/null
cmake --build build-sanitize -j"${DROVER_JOBS:-2}" --target "${tests[@]}"
export DROVER_SOURCE_DIR="$PWD" DROVER_BINARY_DIR="$PWD/build-sanitize"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1
status=0
for test in "${tests[@]}"; do
  echo "sanitized: $test"
  "build-sanitize/bin/$test" --gtest_brief=1 || { echo "sanitized: $test FAILED"; status=1; }
done
exit "$status"
