#!/bin/bash
# #15 target "synthetic --sensor kinect sequences: full <= 1.3x its static twin": the panel's four
# hand-held kinect cells (seed people: 21 2, 22 3, 23 4, 26 4; 240 frames) and each one's static
# twin (same seed and motion, --bodies 0), `pspslam run --dynamic full` on both; ATE RMSE (mm) of
# trajectory.txt and trajectory_refined.txt with the marker body moved onto the camera.
# usage: PSPSLAM=build/apps/pspslam WORK=/tmp/kinect_twin bench/kinect_static_twin.sh
set -euo pipefail
B=${PSPSLAM:-build/apps/pspslam}
W=${WORK:-/tmp/kinect_twin}
PY=${PYTHON:-/usr/bin/python3}
mkdir -p "$W"
for spec in "21 2" "22 3" "23 4" "26 4"; do
  set -- $spec
  seed=$1
  people=$2
  for bodies in "$people" 0; do
    seq=$W/seq_${seed}_b$bodies
    [ -f "$seq/groundtruth.txt" ] || "$B" -q synth --out "$seq" --frames 240 --bodies "$bodies" \
      --seed "$seed" --trajectory handheld --sensor kinect --threads 1 >/dev/null
    out=$W/run_${seed}_b$bodies
    [ -f "$out/stats.json" ] || "$B" -q run --sequence "$seq" --out "$out" --dynamic full \
      >"$W/log_${seed}_b$bodies.txt" 2>&1
    for f in trajectory.txt trajectory_refined.txt; do
      echo "seed $seed bodies $bodies $f $("$B" -q eval --gt "$seq/groundtruth.txt" --est "$out/$f" \
        --gt-body-to-camera "$seq/body_to_camera.txt" --json | "$PY" -c \
        'import json,sys; e=json.load(sys.stdin)["ate"]["error_m"]; print(round(e["rmse"]*1e3,2), e["count"])')"
    done
  done
done
