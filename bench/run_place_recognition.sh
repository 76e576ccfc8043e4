#!/usr/bin/env bash
# Relocalisation and map save/load benchmark (issue #4, "Done when"):
#  1. blackout: frames FROM..FROM+29 are fed black and without depth (`pspslam run --blackout`),
#     so tracking is really lost; reported: frames from the return to the first pose, the method
#     that found it, and the position errors of the poses after the return (run's own SE(3)
#     alignment). With relocalisation on (default) and off (--no-relocalization: only the old
#     recovery against the last reference keyframe).
#  2. save -> load -> localise: `--save-map`, then `--load-map --localization` on the same
#     sequence; reported: position difference per frame between the two runs' trajectories
#     (same timestamps, no alignment: both are in the saved map's world frame).
# On a synthetic static sequence (600 frames, handheld) and on ../shared bonn_crowd_dev
# (--dynamic geometry). Loop closing is off (it is measured by bench/run_loop.sh).
# `uptime` is logged with every run (shared machine).
#
# usage: bench/run_place_recognition.sh [BUILD_DIR (default build)] [WORK_DIR]
set -euo pipefail
source "$(dirname "$0")/common.sh"
build="${1:-$root/build}"
work="${2:-/tmp/pspslam_place}"
require_cli "$build"
mkdir -p "$work"

synthetic="$work/static_600"
if [[ ! -f "$synthetic/groundtruth.txt" ]]; then
  "$cli" synth --out "$synthetic" --frames 600 --bodies 0 --seed 1 > /dev/null
fi

# Largest and RMS position difference between two TUM trajectories at equal timestamps.
compare_trajectories() {  # reference estimate
  python3 - "$1" "$2" <<'PY'
import math, sys
def read(path):
    poses = {}
    for line in open(path):
        if line.startswith('#') or not line.strip():
            continue
        v = line.split()
        poses[round(float(v[0]), 4)] = tuple(float(x) for x in v[1:4])
    return poses
a, b = read(sys.argv[1]), read(sys.argv[2])
common = sorted(set(a) & set(b))
d = [math.dist(a[t], b[t]) for t in common]
rms = math.sqrt(sum(x * x for x in d) / len(d)) if d else float('nan')
print(f"{len(common)} common poses of {len(a)}/{len(b)}: difference RMS {rms:.4f} m, max {max(d) if d else float('nan'):.4f} m")
PY
}

run() {  # label flags...
  local label="$1"
  shift
  echo "--- $label  (load: $(uptime | sed 's/.*load average: //'))"
  "$cli" run --loop-closing off --out "$work/$label" "$@" > "$work/$label.log" 2>&1
  grep -E "^(frames|ATE trajectory.txt|blackout|  +after the return|map saved)" "$work/$label.log" || true
}

cases=("synthetic:$synthetic:off:300:$synthetic/config.yaml")
[[ -d "$shared/data/bonn_crowd_dev" ]] &&
  cases+=("bonn:$shared/data/bonn_crowd_dev:geometry:100:$root/config/bonn.yaml")
for entry in "${cases[@]}"; do
  IFS=: read -r name sequence mode blackout_from config <<< "$entry"
  run "${name}_reference" --sequence "$sequence" --config "$config" --dynamic "$mode" --save-map "$work/$name.pspmap"
  run "${name}_blackout" --sequence "$sequence" --config "$config" --dynamic "$mode" --blackout "$blackout_from:30"
  run "${name}_blackout_norelocalization" --sequence "$sequence" --config "$config" --dynamic "$mode" \
    --blackout "$blackout_from:30" --no-relocalization
  run "${name}_localization" --sequence "$sequence" --config "$config" --dynamic "$mode" \
    --load-map "$work/$name.pspmap" --localization
  echo -n "save -> load -> localise vs the saving run (trajectory_refined.txt): "
  compare_trajectories "$work/${name}_reference/trajectory_refined.txt" \
    "$work/${name}_localization/trajectory.txt"
done
