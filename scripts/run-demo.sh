#!/usr/bin/env bash
# Quick start, command 1: installs what is missing, builds, and runs Drover's main job.
# Until the fleet demo exists, the main job validates and summarises the bundled warehouse.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
exec build/bin/drover topology validate launch/topologies/warehouse.json
