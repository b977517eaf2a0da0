#!/usr/bin/env bash
# The pure libraries' unit tests (topology, carp: no DDS, no processes) built with
# AddressSanitizer and UBSan into build-sanitize/, and run. Those libraries keep raw pointers
# into arenas and timelines between calls (docs/carp.md, docs/timelines.md), where a bug
# would corrupt memory silently; any report fails the run. Called by run-tests.sh after the
# main suite; the build directory is separate, so `build/` keeps its optimised binaries.
set -euo pipefail
cd "$(dirname "$0")/.."
tests=(test_topology test_timeline test_carp)
DROVER_BUILD_DIR=build-sanitize DROVER_BUILD_TARGETS="${tests[*]}" \
  ./scripts/build.sh -DDROVER_SANITIZE=ON
export DROVER_SOURCE_DIR="$PWD" DROVER_BINARY_DIR="$PWD/build-sanitize"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1
status=0
for test in "${tests[@]}"; do
  echo "sanitized: $test"
  "build-sanitize/bin/$test" --gtest_brief=1 || { echo "sanitized: $test FAILED"; status=1; }
done
exit "$status"
