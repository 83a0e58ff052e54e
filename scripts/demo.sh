#!/usr/bin/env bash
# The demo on a fresh machine: installs what is missing, builds, renders a few hand poses
# with and without objects from several viewpoints, builds (or reuses) the default database
# and its index, runs small versions of the feature and nearest-neighbour studies, measures
# the renderer and the whole estimator, and then does the real thing: renders a sequence of
# a hand with a bare forearm grasping an object the database does not hold, estimates its
# poses, and writes the JSON lines, the overlay video and the errors against the truth.
# Everything it writes goes to out/demo/.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
nphand="$root/build/apps/nphand"
out="$root/out/demo"
mkdir -p "$out"

render() { "$nphand" render --out "$out" "$@" | sed 's/^/  /'; }
echo "demo: rendering poses and objects into $out"
render --name rest_palm --pose rest
render --name relaxed_back --pose relaxed --azimuth 180
render --name fist_side --pose fist --azimuth 60 --elevation 20
render --name point_roll --pose point --azimuth -30 --roll 40
render --name ball_in_palm --pose relaxed --object sphere --object-size 0.035 \
  --object-at 0.085,0,-0.045 --azimuth 20 --elevation 15
render --name bar_grip --pose fist --object cylinder --object-size 0.015,0.16 \
  --object-at 0.075,0.0,-0.03 --object-rotate 90,0,0 --azimuth 200 --elevation 10
render --name left_pinch --hand left --pose pinch --azimuth 10 --elevation -10

echo "demo: the 33 grasps of the GRASP taxonomy, pre-shape and final grasp"
render --name taxonomy --grasp all --azimuth 25 --elevation 25 --step 0
render --name taxonomy --grasp all --azimuth 25 --elevation 25
render --name power_sphere --grasp power_sphere --azimuth 30 --elevation 10

echo "demo: the default database (33 grasps x 5 steps x with/without object x 648 viewpoints, then 16 gestures x 5 steps x 648 viewpoints)"
"$nphand" db build --reuse --out "$root/out/nphand.db"
"$nphand" db info "$root/out/nphand.db" --json | tee "$out/db_info.json"
echo
echo "demo: feature study (paper Fig. 4) on 500 left-out entries, HOG 8x8x8 against pose space"
"$nphand" eval features --db "$root/out/nphand.db" --queries 500 --features joints,hog8x8x8 --out "$out" --name feature_study

echo "demo: the default index of the database (hnswlib HNSW, chosen in docs/ann_study.md)"
"$nphand" index build --reuse --db "$root/out/nphand.db" --json | tee "$out/index_build.json"
echo
echo "demo: nearest-neighbour study (paper Fig. 5) on 100 held-out renders, exact search against the default"
"$nphand" eval ann --db "$root/out/nphand.db" --backends exact,hnswlib --fractions 0.25,1 --queries 100 \
  --out "$out" --name ann_study

echo "demo: renderer speed (label images of 128x128, hand + object, one core)"
"$nphand" bench render --json | tee "$out/bench_render.json"
echo "demo: the whole estimator's speed (640x480 frames with a face beside the hand, K = 500, one core)"
"$nphand" bench pipeline --json | tee "$out/bench_pipeline.json"

echo "demo: a rendered sequence: a hand with a bare forearm closing onto a cylinder 0.8 times the database's, a rolling camera"
seq="$out/sequence"
"$nphand" sequence --grasp 1 --object-scale 0.8 --forearm bare --background clutter --face --frames 120 \
  --seed 11 --video --out "$seq"
hand_length=$(sed -n 's/.*"hand_length_m": \([0-9.]*\).*/\1/p' "$seq/sequence.json")
echo "demo: estimating its poses"
"$nphand" estimate --db "$root/out/nphand.db" --input "$seq/frames" --hand-length "$hand_length" \
  --out "$out/poses.jsonl" --overlay "$out/overlay.mp4" --bvh "$out/motion.bvh" --gltf "$out/motion.glb"
echo "demo: the motion files read back against the poses"
"$nphand" eval motion --poses "$out/poses.jsonl" --bvh "$out/motion.bvh" --gltf "$out/motion.glb"
echo "demo: errors against the ground truth"
"$nphand" eval poses --truth "$seq/truth.jsonl" --poses "$out/poses.jsonl" --out "$out" --name errors
realdev="$root/../shared/real-dev"
if [ -f "$realdev/labels.jsonl" ]; then
  echo "demo: real photographs and video (real-dev, its labelled hand sides given), scored as real-dev's reference does"
  "$nphand" eval real --labels "$realdev/labels.jsonl" --out "$out"
else
  echo "demo: skipping nphand eval real: $realdev is not here (real-dev is not shipped with nphand)"
fi
echo "demo: done; images in $out"
echo "  poses:   $out/poses.jsonl (docs/FORMAT.md)"
echo "  overlay: $out/overlay.mp4"
echo "  motion:  $out/motion.bvh, $out/motion.glb (the rigged hand, animated)"
echo "  errors:  $out/errors.png, $out/errors.json"
if [ -f "$realdev/labels.jsonl" ]; then echo "  real:    $out/real.json, $out/real_contact.png"; fi
