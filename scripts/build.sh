#!/usr/bin/env bash
# Configures and builds nphand into a build folder.
# Usage: scripts/build.sh [--sanitize]   (build/ or, with --sanitize, build-asan/)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ "${1:-}" = "--sanitize" ]; then
  dir="$root/build-asan"
  # -O1 -g1: what the sanitizers' authors advise (usable speed, line numbers in reports) and
  # half the compile time of -O2 -g on this project's largest units.
  flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DNPHAND_SANITIZE=ON
         -DNPHAND_BUILD_BENCH=OFF)
else
  dir="$root/build"
  flags=(-DCMAKE_BUILD_TYPE=Release)
fi
cmake -S "$root" -B "$dir" -G Ninja -DNPHAND_WERROR=ON "${flags[@]}" >/dev/null
cmake --build "$dir" --parallel "$(nproc)"
