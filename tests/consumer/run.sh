#!/usr/bin/env bash
# CTest's package test: installs the build into a scratch prefix, checks that the project's
# own compile flags stayed private and the internal headers out, that the installed nphand
# and the Python module find the hand mesh in the prefix's share folder, then builds tests/consumer against the
# install with find_package(nphand) and runs it.
# Usage: tests/consumer/run.sh <build dir>
set -euo pipefail
build="$1"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
prefix="$scratch/prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
if grep -n -e "-Werror" -e "-fsanitize" -e "-Wall" "$prefix"/lib/cmake/nphand/*.cmake; then
  echo "consumer: the installed package carries the project's compile flags" >&2
  exit 1
fi
for internal in model/gltf_accessor.h index/body.h index/index_file.h index/faiss_index.h index/flann_index.h index/hnswlib_index.h; do
  if [ -e "$prefix/include/nphand/$internal" ]; then
    echo "consumer: internal header $internal was installed" >&2
    exit 1
  fi
done
cmake -S "$here" -B "$scratch/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$scratch/build" >/dev/null
"$prefix/bin/nphand" --version
env -u NPHAND_ASSET_DIR "$prefix/bin/nphand" render --help | grep -F -- "--asset-dir TEXT=$prefix/share/nphand/hand"
env -u NPHAND_ASSET_DIR "$prefix/bin/nphand" render --pose fist --out "$scratch/render"
# The Python module, where the install put it, finds the mesh in the prefix too.
for module in "$prefix"/lib/python3*/dist-packages/nphand.*.so; do
  [ -e "$module" ] || continue
  env -u NPHAND_ASSET_DIR PYTHONPATH="$(dirname "$module")" /usr/bin/python3 -c \
    "import nphand; print('python: nphand', nphand.__version__, 'from', nphand.__file__); print('python: hand mesh in', nphand.default_asset_dir())" \
    | tee "$scratch/python.txt"
  grep -qF "hand mesh in $prefix/share/nphand/hand" "$scratch/python.txt"
done
# A program of one's own finds the mesh in the prefix the install was configured for; this
# scratch prefix is not that one, so it is named the way such a user would.
NPHAND_ASSET_DIR="$prefix/share/nphand/hand" "$scratch/build/consumer" "$scratch/work"
