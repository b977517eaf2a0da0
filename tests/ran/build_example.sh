#!/usr/bin/env bash
# Installs Drover's SDK into a temporary prefix, builds examples/minimal_ran out of tree
# against it with find_package(drover), and runs the example's self-test (which checks its
# own outcome).
# Usage: build_example.sh BINARY_DIR SOURCE_DIR [extra cmake arguments for the example]
set -euo pipefail
binary_dir=$1
source_dir=$2
shift 2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake --install "$binary_dir" --prefix "$work/prefix" --component sdk >/dev/null
cmake -S "$source_dir/examples/minimal_ran" -B "$work/build" \
  -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$work/build" -j1
"$work/build/minimal_ran" --self-test
# Bad usage is exit 2, not a crash or a hang.
status=0
"$work/build/minimal_ran" --bogus 2>/dev/null || status=$?
[[ $status -eq 2 ]] || { echo "minimal_ran --bogus exited $status, expected 2" >&2; exit 1; }
