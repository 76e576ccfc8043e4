#!/usr/bin/env bash
# Loop closing benchmark (issue #4, "Done when"): ATE with loop closing on vs off on a synthetic
# sequence that revisits its start after a long loop, and on ../shared bonn_crowd_dev
# (--dynamic geometry) to check loop closing does not hurt a sequence without a loop.
#
# The synthetic sequence: 900 frames (30 s), static room (--bodies 0), camera on the loop
# trajectory for 1.5 turns (--loop-turns 1.5): one full turn, then half a turn over the
# start again, long enough for ORB-SLAM2's covisibility consistency (3 consecutive keyframes).
#
# Reported: ATE RMSE of trajectory_refined.txt (every frame moved with the keyframes around it
# after loop correction and global BA: the final trajectory) and of
# trajectory.txt (poses as tracked online; a correction cannot change frames already written).
# Medians over RUNS runs per cell. `uptime` is logged with every run (shared machine).
#
# usage: bench/run_loop.sh [BUILD_DIR (default build)] [WORK_DIR (default /tmp/pspslam_loop)]
#        RUNS=3 BONN=1 bench/run_loop.sh ...      (BONN=0 skips bonn_crowd_dev)
set -euo pipefail
source "$(dirname "$0")/common.sh"
build="${1:-$root/build}"
work="${2:-/tmp/pspslam_loop}"
runs="${RUNS:-3}"
bonn="${BONN:-1}"
require_cli "$build"
mkdir -p "$work"

sequence="$work/loop_900_1.5turns"
if [[ ! -f "$sequence/groundtruth.txt" ]]; then
  "$cli" synth --out "$sequence" --frames 900 --bodies 0 --trajectory loop --loop-turns 1.5 --seed 1
fi

json_value() {  # file dotted.key
  python3 -c "
import json, sys
value = json.load(open(sys.argv[1]))
for key in sys.argv[2].split('.'):
    value = value.get(key, {}) if isinstance(value, dict) else {}
print(value if value != {} else 'nan')" "$@"
}

results="$work/results.csv"
echo "sequence,loop_closing,run,ate_refined,ate_tracked,loops_closed,global_ba,seconds,load" > "$results"
run_cell() {  # label sequence mode run [extra flags]
  local label="$1" seq="$2" mode="$3" r="$4"
  shift 4
  local out="$work/out_${label}_${mode}_$r"
  local load
  load="$(uptime | sed 's/.*load average: //' | cut -d, -f1)"
  "$cli" run --sequence "$seq" --out "$out" --loop-closing "$mode" "$@" > "$out.log" 2>&1
  local stats="$out/stats.json"
  echo "$label,$mode,$r,$(json_value "$stats" ate_refined.rmse),$(json_value "$stats" ate.rmse),$(json_value "$stats" loops.closed),$(json_value "$stats" loops.global_ba_applied),$(json_value "$stats" seconds),$load" >> "$results"
  tail -n 1 "$results"
}

for r in $(seq 1 "$runs"); do
  for mode in off on; do
    run_cell synth_loop "$sequence" "$mode" "$r" --dynamic off
  done
done
if [[ "$bonn" == 1 && -d "$shared/data/bonn_crowd_dev" ]]; then
  for r in $(seq 1 "$runs"); do
    for mode in off on; do
      run_cell bonn_crowd_dev "$shared/data/bonn_crowd_dev" "$mode" "$r" --dynamic geometry \
        --config "$root/config/bonn.yaml"
    done
  done
fi

# Median table.
python3 - "$results" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
cells = {}
for row in rows:
    cells.setdefault((row["sequence"], row["loop_closing"]), []).append(row)
print("\n| sequence | loop closing | runs | ATE refined median (m) | ATE tracked median (m) | loops closed | global BA applied |")
print("|---|---|---|---|---|---|---|")
medians = {}
for (sequence, mode), group in sorted(cells.items()):
    refined = statistics.median(float(r["ate_refined"]) for r in group)
    tracked = statistics.median(float(r["ate_tracked"]) for r in group)
    medians[(sequence, mode)] = refined
    loops = "/".join(r["loops_closed"] for r in group)
    gba = "/".join(r["global_ba"] for r in group)
    print(f"| {sequence} | {mode} | {len(group)} | {refined:.4f} | {tracked:.4f} | {loops} | {gba} |")
for sequence in sorted({s for s, _ in medians}):
    if (sequence, "on") in medians and (sequence, "off") in medians:
        on, off = medians[(sequence, "on")], medians[(sequence, "off")]
        print(f"{sequence}: refined ATE on/off = {on:.4f}/{off:.4f} = {on / off:.2f}")
PY
