#!/usr/bin/env bash
# Quick start, command 1: installs what is missing, builds, and runs Drover's main job: the
# bundled warehouse (launch/warehouse.json: 8 simulated vehicles with their logical agents,
# two topology agents, a routing agent and a load generator) for 600 simulated seconds at
# time factor 10 (about a minute), then prints the summary (orders finished / failed, mean
# lead time). Extra arguments go to `drover launch`, e.g. --trace run.jsonl.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
exec build/bin/drover launch launch/warehouse.json --duration 600 "$@"
