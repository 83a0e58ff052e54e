#!/usr/bin/env bash
# Configures and builds nphand into a build folder.
# Usage: scripts/build.sh [--sanitize]   (build/ or, with --sanitize, build-asan/)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ "${1:-}" = "--sanitize" ]; then
  dir="$root/build-asan"
  flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DNPHAND_SANITIZE=ON -DNPHAND_BUILD_BENCH=OFF)
else
  dir="$root/build"
  flags=(-DCMAKE_BUILD_TYPE=Release)
fi
cmake -S "$root" -B "$dir" -G Ninja -DNPHAND_WERROR=ON "${flags[@]}" >/dev/null
cmake --build "$dir" --parallel "$(nproc)"
