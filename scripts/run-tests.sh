#!/usr/bin/env bash
# Quick start, command 2: installs what is missing, builds, and runs the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
# Crashed DDS processes can leave shared-memory segments behind; clean before and after.
fastdds shm clean >/dev/null 2>&1 || true
status=0
ctest --test-dir build --output-on-failure -j"${DROVER_TEST_JOBS:-2}" --timeout 600 || status=$?
fastdds shm clean >/dev/null 2>&1 || true
# Then the pure libraries' tests again under AddressSanitizer and UBSan.
./scripts/run-sanitized-tests.sh || status=1
exit "$status"
