#!/usr/bin/env bash
# Installs Drover's SDK into a temporary prefix, builds examples/minimal_ran out of tree
# against it with find_package(drover), runs the example's self-test (which checks its own
# outcome), then attaches it as the RAN of a fleet started by `drover launch` (no simulated
# vehicle) and sends it a transport order that must finish: what a vehicle integrator does
# with the SDK (docs/ran-sdk.md "Attaching a RAN to a fleet").
# Usage: build_example.sh BINARY_DIR SOURCE_DIR [extra cmake arguments for the example]
set -euo pipefail
binary_dir=$1
source_dir=$2
shift 2
readonly domain=25  # this test's own DDS domain
work=$(mktemp -d)
pids=()
cleanup() {
  local pid
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 143' TERM INT  # a timeout kills us with TERM: clean up all the same

cmake --install "$binary_dir" --prefix "$work/prefix" --component sdk >/dev/null
cmake -S "$source_dir/examples/minimal_ran" -B "$work/build" \
  -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$work/build" -j1
"$work/build/minimal_ran" --self-test
# Bad usage is exit 2, not a crash or a hang.
status=0
"$work/build/minimal_ran" --bogus 2>/dev/null || status=$?
[[ $status -eq 2 ]] || { echo "minimal_ran --bogus exited $status, expected 2" >&2; exit 1; }

# launch/minimal_ran.json: the fleet of docs/ran-sdk.md, its logical agent planning with the
# example vehicle's speed and outline; no simulated vehicle.
# Both end by themselves too (in 400 s, within the test's 600 s), should a SIGKILL leave them.
"$binary_dir/bin/drover" launch "$source_dir/launch/minimal_ran.json" --domain "$domain" --duration 400 \
  --state-dir "$work/state" >"$work/launch.log" 2>&1 &
pids+=($!)
timeout 400 "$work/build/minimal_ran" V1 "$domain" >"$work/ran.log" 2>&1 &
pids+=($!)

# Runs droverctl in the background: `wait` lets a TERM (the test's timeout) in at once.
droverctl() {
  "$binary_dir/bin/droverctl" "$@" >"$work/droverctl.out" 2>&1 &
  local status=0
  wait $! || status=$?
  cat "$work/droverctl.out"
  return $status
}

# Up to a minute for the agents to come up and answer, two for the order (about 12 m of
# driving there and back, a load and an unload).
if ! droverctl order send V1 left-2:load left-0:unload --name example-order --wait 120 --timeout 60 \
       --domain "$domain"; then
  echo "--- launch ---" >&2; cat "$work/launch.log" >&2
  echo "--- minimal_ran ---" >&2; cat "$work/ran.log" >&2
  exit 1
fi
# The example advertises that it only loads and unloads: an order to charge is refused when
# it is sent (exit 1), naming what the vehicle performs.
status=0
droverctl order send V1 left-2:charge --timeout 60 --domain "$domain" >/dev/null || status=$?
refusal=$(cat "$work/droverctl.out")
if [[ $status -ne 1 || $refusal != *"does not perform 'charge' (its RAN performs: load, unload)"* ]]; then
  echo "an order to charge: exit $status, expected 1 and the refusal: $refusal" >&2
  exit 1
fi
