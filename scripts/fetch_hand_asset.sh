#!/usr/bin/env bash
# Fetches the MIT-licensed rigged generic-hand meshes from the npm package
# @webxr-input-profiles/assets (pinned version), verifies pinned sha256 sums and
# keeps only the two .glb files and the package's licence in an ignored cache (default: <repo>/.cache/hand).
# Idempotent: does nothing when the verified files are already there.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cache="${NPHAND_ASSET_DIR:-$here/../.cache/hand}"
version="1.0.20"
tarball="webxr-input-profiles-assets-${version}.tgz"
tarball_sha="30df2a2268220fc0d0e034bed1550aabdd7a2500573c5216f64fc70d59c3d91e"
declare -A file_sha=(
  [right.glb]="291790c14f7f88a7f9bd35330c47392ed8e8d395ae6728f4bb7089f1bc1f2b96"
  [left.glb]="bc67783144944ea1cda54d9247885825ea5fb9d4651469fe7d00be517a5c2b87"
  [LICENSE.md]="0ef0c87e8ffdd0681f332dc3b39f284dee2166d1f853fabc3853884fe81a6f30"
)

verified() {
  for f in "${!file_sha[@]}"; do
    [ -f "$cache/$f" ] || return 1
    echo "${file_sha[$f]}  $cache/$f" | sha256sum --check --status || return 1
  done
}

mkdir -p "$cache"
if verified; then
  echo "setup: hand mesh already in $cache"
  exit 0
fi

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
echo "setup: fetching @webxr-input-profiles/assets@${version} with npm (~94 MB, once)"
(cd "$work" && npm pack --silent "@webxr-input-profiles/assets@${version}" >/dev/null)
echo "${tarball_sha}  $work/$tarball" | sha256sum --check --status \
  || { echo "setup: $tarball: sha256 mismatch" >&2; exit 1; }
tar -xzf "$work/$tarball" -C "$work" package/LICENSE.md \
  package/dist/profiles/generic-hand/right.glb package/dist/profiles/generic-hand/left.glb
for f in "${!file_sha[@]}"; do
  src="$work/package/dist/profiles/generic-hand/$f"
  [ "$f" = LICENSE.md ] && src="$work/package/LICENSE.md"
  echo "${file_sha[$f]}  $src" | sha256sum --check --status \
    || { echo "setup: $f: sha256 mismatch" >&2; exit 1; }
  cp "$src" "$cache/$f.tmp" && mv "$cache/$f.tmp" "$cache/$f"
done
echo "setup: hand mesh verified in $cache"
