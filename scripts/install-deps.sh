#!/usr/bin/env bash
# Installs, with apt-get, the Debian bookworm packages Drover needs to build and test.
# Idempotent: packages already installed are left alone; nothing is downloaded otherwise.
set -euo pipefail

packages=(
  build-essential cmake git pkg-config ccache
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools
  libeigen3-dev libboost-dev
  nlohmann-json3-dev libspdlog-dev libfmt-dev libcli11-dev
  libsqlite3-dev libgtest-dev
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
