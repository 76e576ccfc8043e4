#!/bin/bash
# Issue #15 item 2: how much of the tracking error each Kinect fault of `pspslam synth --sensor
# kinect` causes. Per seed: the ideal twin, kinect with every fault, and kinect with one fault off
# (marker is not run: it changes only groundtruth.txt; its share is the ATE without
# --gt-body-to-camera). Each sequence: 240 frames, 3 people; `pspslam run --dynamic full`.
# Prints per run: seed, sequence, ATE RMSE (mm, `pspslam eval`, trajectory_refined.txt), and the
# low/high-frequency split (bench/trajectory_error_bands.py, 9-frame window). With BONN=1 also
# bonn_crowd_dev with config/bonn.yaml.
#   usage: PYTHON=/usr/bin/python3 SEEDS="1 2 3" WORK=/tmp/kinect_faults PSPSLAM=build/apps/pspslam bench/run_kinect_faults.sh
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PSPSLAM=$(realpath "${PSPSLAM:-$ROOT/build/apps/pspslam}")
WORK=${WORK:-/tmp/kinect_faults}
SEEDS=${SEEDS:-1}
SHARED=${PSPSLAM_SHARED:-$ROOT/../shared}
PYTHON=${PYTHON:-python3}  # needs numpy (Debian: /usr/bin/python3 with python3-numpy)
FAULTS="depth-noise holes sync-offset rolling-shutter motion-blur exposure distortion handheld-motion"
mkdir -p "$WORK"

evaluate() {  # name sequence-folder-or-gt run-folder [body_to_camera]
  local gt=$1 est=$2 body=${3:-}
  local ate bands
  ate=$("$PSPSLAM" -q eval --gt "$gt" --est "$est" ${body:+--gt-body-to-camera "$body"} --json |
    "$PYTHON" -c "import json,sys; print(f\"{json.load(sys.stdin)['ate']['error_m']['rmse']*1e3:.1f}\")")
  bands=$("$PYTHON" "$ROOT/bench/trajectory_error_bands.py" "$gt" "$est" \
    ${body:+--gt-body-to-camera "$body"} | sed -n 's/^low-frequency (9-frame average) \(.*\) mm, high-frequency \(.*\) mm$/\1 \2/p')
  echo "$ate $bands"
}

echo "# seed sequence ATE_mm low_mm high_mm (ATE_without_body_to_camera_mm for kinect)"
for seed in $SEEDS; do
  for name in ideal kinect $(for f in $FAULTS; do echo "no_$f"; done); do
    seq=$WORK/seq${seed}_$name out=$WORK/out${seed}_$name
    case $name in
      ideal) flags="--sensor ideal" ;;
      kinect) flags="--sensor kinect" ;;
      *) flags="--sensor kinect --no-fault ${name#no_}" ;;
    esac
    [ -f "$seq/groundtruth.txt" ] || "$PSPSLAM" -q synth --out "$seq" --frames 240 --bodies 3 \
      --seed "$seed" $flags > /dev/null
    [ -f "$out/stats.json" ] || "$PSPSLAM" -q run --sequence "$seq" --dynamic full \
      --out "$out" > "$WORK/run${seed}_$name.log" 2>&1
    body=""
    [ -f "$seq/body_to_camera.txt" ] && body=$seq/body_to_camera.txt
    line="$seed $name $(evaluate "$seq/groundtruth.txt" "$out/trajectory_refined.txt" "$body")"
    if [ -n "$body" ]; then
      line="$line $(evaluate "$seq/groundtruth.txt" "$out/trajectory_refined.txt" | cut -d' ' -f1)"
    fi
    echo "$line"
  done
done
if [ "${BONN:-0}" = 1 ]; then
  out=$WORK/out_bonn
  [ -f "$out/stats.json" ] || "$PSPSLAM" -q run --sequence "$SHARED/data/bonn_crowd_dev" \
    --config "$ROOT/config/bonn.yaml" --dynamic full --out "$out" > "$WORK/run_bonn.log" 2>&1
  echo "- bonn_crowd_dev $(evaluate "$SHARED/data/bonn_crowd_dev/groundtruth.txt" \
    "$out/trajectory_refined.txt")"
fi
