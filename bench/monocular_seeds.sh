#!/bin/bash
# Issue #16, monocular: synthetic dynamic sequences of the demo's kind (`pspslam synth --frames
# 300 --bodies 3 --seed N`) read as colour only (`run --sensor monocular --dynamic full`), for a
# baseline binary and a variant, one deterministic run each. Per seed and binary: the frame the
# map started at, frames placed before it, frames with a pose (of 300), Sim(3) ATE RMSE (mm) of
# trajectory.txt and trajectory_refined.txt over the frames each file holds, from stats.json.
#   usage: BASE=path/to/pspslam VARIANT=build/apps/pspslam SEEDS="1 2 3" WORK=/tmp/mono_seeds \
#          bench/monocular_seeds.sh
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
VARIANT=$(realpath "${VARIANT:-$ROOT/build/apps/pspslam}")
BASE=${BASE:+$(realpath "$BASE")}
WORK=${WORK:-/tmp/mono_seeds}
SEEDS=${SEEDS:-1 2 3 4 5 6 7 8 9 10 11 12}
PYTHON=${PYTHON:-python3}
mkdir -p "$WORK"

summary() {  # stats.json -> "start placed posed online final"
  "$PYTHON" - "$1" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
m = s.get("monocular", {})
start = m.get("initialised_at_frame")
placed = m.get("placed_before_initialisation", 0)
posed = s["frames"] - s["lost_frames"]
mm = lambda k: f"{s[k]['rmse'] * 1e3:.1f}" if s.get(k) else "-"
print(f"{start} {placed} {posed} {mm('ate')} {mm('ate_refined')}")
PY
}

echo "# seed binary start placed posed/frames online_mm final_mm"
for seed in $SEEDS; do
  seq=$WORK/seq_$seed
  [ -f "$seq/groundtruth.txt" ] || "$VARIANT" -q synth --out "$seq" --frames 300 --bodies 3 \
    --seed "$seed" > /dev/null
  for name in ${BASE:+base} variant; do
    binary=$VARIANT
    [ "$name" = base ] && binary=$BASE
    out=$WORK/out_${seed}_$name
    "$binary" -q run --sequence "$seq" --sensor monocular --dynamic full --out "$out" \
      > "$out.log" 2>&1 || { echo "$seed $name failed (see $out.log)"; continue; }
    read -r start placed posed online final < <(summary "$out/stats.json")
    echo "$seed $name $start $placed $posed/300 $online $final"
  done
done
