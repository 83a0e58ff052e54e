#!/usr/bin/env bash
# Runs every libFuzzer target (tests/fuzz) for a given time each, on top of seeds made from
# real small files and the corpus kept from earlier runs (.cache/fuzz/), and prints a line
# per target: executions, corpus size, crashes. Exits non-zero if any target crashed (the
# input is kept in .cache/fuzz/crashes/ and belongs in a regression test).
# Usage: scripts/fuzz.sh [--seconds N] [--target NAME]   (default: 60 s for each target)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds=60
targets=(db_file db_content db_resume glb index index_body poses frames motion)
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --target) targets=("$2"); shift 2 ;;
    *) echo "usage: scripts/fuzz.sh [--seconds N] [--target NAME]" >&2; exit 2 ;;
  esac
done

"$root/scripts/setup.sh"
fuzz_packages=(clang libclang-rt-14-dev libomp-14-dev)
if [ "$(dpkg-query -W -f='${Status}\n' "${fuzz_packages[@]}" 2>/dev/null | grep -c 'install ok installed')" -eq 3 ]; then
  echo "fuzz: clang, libFuzzer and OpenMP for clang already installed"
else
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${fuzz_packages[@]}"
fi

build="$root/build-fuzz"
# -O1 -g1: libFuzzer's own advice (-g -O1), and a quicker build than -O2 -g.
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DNPHAND_FUZZ=ON -DNPHAND_BUILD_TESTS=OFF -DNPHAND_BUILD_BENCH=OFF \
  >/dev/null
cmake --build "$build" --parallel "$(nproc)" --target nphand frame_seeds "${targets[@]/#/fuzz_}"

# Seeds: a real small database (a shard of it, and one with a gesture), split the ways the
# targets take them.
cache="$root/.cache/fuzz"
seeds="$cache/seeds"
rm -rf "$seeds" "$cache/crashes"
mkdir -p "$seeds" "$cache/crashes"
export ASAN_OPTIONS="detect_leaks=1"
"$build/apps/nphand" db build --grasps 1 --gestures none --directions 2 --threads 1 --quiet --out "$seeds/tiny.db" >/dev/null
"$build/apps/nphand" db build --grasps 1 --gestures none --directions 2 --threads 1 --quiet --shard 1/3 --out "$seeds/shard.db" >/dev/null
"$build/apps/nphand" db build --grasps 1 --gestures fist --directions 2 --threads 1 --quiet --out "$seeds/gestures.db" >/dev/null
python3 - "$seeds" <<'PY'
import os, struct, sys, zlib
seeds = sys.argv[1]
for t in ("db_file", "db_content", "db_resume", "glb", "index", "index_body"):
    os.makedirs(os.path.join(seeds, t), exist_ok=True)
for name in ("tiny", "shard", "gestures"):
    data = open(os.path.join(seeds, name + ".db"), "rb").read()
    header_len = struct.unpack_from("<I", data, 12)[0]
    header = data[16:16 + header_len]
    start = (16 + header_len + 4 + 63) // 64 * 64
    records = data[start:len(data) - 20]
    open(os.path.join(seeds, "db_file", name), "wb").write(data)
    open(os.path.join(seeds, "db_content", name), "wb").write(struct.pack("<I", header_len) + header + records)
    if name == "tiny":
        # An interrupted build: the prologue, blocks of 4 records with their checksums, a torn record.
        record = len(records) // 20
        for kept in (0, 8, 20):
            partial = data[:start] + records[:kept * record] + records[kept * record:kept * record + 100]
            blocks = b"NPHBLKS1" + b"".join(
                struct.pack("<QI", 4, zlib.crc32(records[b * record:(b + 4) * record]))
                for b in range(0, kept, 4))
            open(os.path.join(seeds, "db_resume", "kept%d" % kept), "wb").write(
                struct.pack("<I", len(partial)) + partial + blocks)
PY
cp "$root/.cache/hand/right.glb" "$root/.cache/hand/left.glb" "$seeds/glb/"
"$build/apps/nphand" index build --db "$seeds/tiny.db" --out "$seeds/index/tiny.idx" >/dev/null
# index_body: a backend byte (the target's order) and a real body of that backend.
selector=0
for backend in faiss-hnsw hnswlib hnswlib-sq8 faiss-ivf; do
  "$build/apps/nphand" index build --db "$seeds/tiny.db" --backend "$backend" --out "$seeds/$backend.idx" >/dev/null 2>&1
  python3 - "$seeds/$backend.idx" "$seeds/index_body/$backend" "$selector" <<'PY'
import struct, sys
data = open(sys.argv[1], "rb").read()
meta_len = struct.unpack_from("<I", data, 12)[0]
body = data[16 + meta_len + 8:len(data) - 4]
open(sys.argv[2], "wb").write(bytes([int(sys.argv[3])]) + body)
PY
  selector=$((selector + 1))
done
export NPHAND_FUZZ_DB="$seeds/tiny.db"  # the database the index target loads its inputs against
# poses: a short rendered sequence's truth, and the poses estimated on it as the seed.
mkdir -p "$seeds/poses"
"$build/apps/nphand" sequence --frames 3 --width 96 --height 72 --distance 0.3 --grasp 1 --video --out "$seeds/sequence" >/dev/null 2>&1
"$build/apps/nphand" estimate --db "$seeds/tiny.db" --index "$seeds/index/tiny.idx" --input "$seeds/sequence/frames" \
  --k 20 --max-distance 2 --top --no-faces --out "$seeds/poses/estimated.jsonl" >/dev/null 2>&1
cp "$seeds/sequence/truth.jsonl" "$seeds/poses/truth.jsonl"
# motion: a run's BVH and glTF (if it found a hand) behind the target's selector byte (0:
# BVH, 1: glTF).
mkdir -p "$seeds/motion"
"$build/apps/nphand" estimate --db "$seeds/tiny.db" --index "$seeds/index/tiny.idx" --input "$seeds/sequence/frames" \
  --k 20 --max-distance 2 --no-faces --out "$seeds/motion.jsonl" --bvh "$seeds/motion.bvh" --gltf "$seeds/motion.glb" \
  >/dev/null 2>&1 || true
[ -f "$seeds/motion.bvh" ] && { printf '\x00'; cat "$seeds/motion.bvh"; } >"$seeds/motion/motion.bvh"
[ -f "$seeds/motion.glb" ] && { printf '\x01'; cat "$seeds/motion.glb"; } >"$seeds/motion/motion.glb"
export NPHAND_FUZZ_TRUTH="$seeds/sequence/truth.jsonl"
# frames: the sequence's first frame as PNG, JPEG (whole and cut short) and BMP, its video
# and a Motion JPEG AVI, each behind the target's selector byte.
"$build/tests/fuzz/frame_seeds" "$seeds/sequence/frames" "$seeds/sequence/video.mp4" "$seeds/frames"

failed=0
for t in "${targets[@]}"; do
  corpus="$cache/corpus/$t"
  mkdir -p "$corpus"
  log="$cache/$t.log"
  status=0
  "$build/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -print_final_stats=1 -rss_limit_mb=4096 \
    -artifact_prefix="$cache/crashes/${t}-" "$corpus" "$seeds/$t" >"$log" 2>&1 || status=$?
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  crashes=$(find "$cache/crashes" -name "${t}-*" | wc -l)
  [ "$status" -ne 0 ] && [ "$crashes" -eq 0 ] && crashes=1
  echo "fuzz: $t: ${execs:-0} executions in ${seconds} s, corpus $(find "$corpus" -type f | wc -l) inputs, crashes $crashes"
  if [ "$crashes" -ne 0 ]; then
    failed=1
    tail -40 "$log"
  fi
done
exit $failed
