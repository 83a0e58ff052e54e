#!/usr/bin/env bash
# Installs what nphand needs on a fresh Debian 12 machine, idempotently:
# the Debian packages (build tools and libraries) and the hand mesh asset.
# Usage: scripts/setup.sh            (packages + asset)
#        scripts/setup.sh --asset    (asset only)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

packages=(
  build-essential cmake ninja-build pkg-config
  libopencv-dev opencv-data libeigen3-dev libtinygltf-dev libstb-dev
  libfaiss-dev libhnswlib-dev libflann-dev liblz4-dev
  nlohmann-json3-dev libcli11-dev pybind11-dev python3-dev python3-numpy python3-pytest
  libgtest-dev libgmock-dev libbenchmark-dev
  libssl-dev zlib1g-dev libopenblas0-pthread nodejs
)

install_packages() {
  local missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    echo "setup: Debian packages already installed"
    return
  fi
  echo "setup: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

if [ "${1:-}" != "--asset" ]; then
  install_packages
fi
"$here/fetch_hand_asset.sh"
