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
# trajectory.txt (poses as tracked online; a correction cannot change frames already written),
# and, per run, the split of bench/loop_error_split.py: the final keyframe poses' ATE and the
# final trajectory's error at the keyframe frames / at the frames between them (issue #15 item 5).
# Medians over RUNS runs per cell. `uptime` is logged with every run (shared machine).
#
# usage: bench/run_loop.sh [BUILD_DIR (default build)] [WORK_DIR (default /tmp/pspslam_loop)]
#        RUNS=3 BONN=1 bench/run_loop.sh ...      (BONN=0 skips bonn_crowd_dev)
#        LOOPS="1:1.5 2:1.5 4:1.75" ...            synthetic loops as SEED:TURNS (default "1:1.5")
#        OFF_RUNS=1 ...                            runs without loop closing (default RUNS; they
#                                                  are deterministic: one is enough)
#        RUN_FLAGS="--due-keyframes" ...           extra `pspslam run` flags for every run
#        SENSOR=monocular ...                      colour only (Sim(3) loop closing; ATE Sim(3)
#                                                  aligned; no keyframe split; bonn_crowd_dev
#                                                  with --dynamic full, which runs as semantic)
set -euo pipefail
source "$(dirname "$0")/common.sh"
build="${1:-$root/build}"
work="${2:-/tmp/pspslam_loop}"
runs="${RUNS:-3}"
off_runs="${OFF_RUNS:-$runs}"
bonn="${BONN:-1}"
loops="${LOOPS:-1:1.5}"
sensor="${SENSOR:-rgbd}"
read -r -a run_flags <<< "${RUN_FLAGS:-}"
bonn_dynamic=geometry
if [[ "$sensor" == monocular ]]; then
  run_flags+=(--sensor monocular)
  bonn_dynamic=full
fi
require_cli "$build"
mkdir -p "$work"
python_numpy=/usr/bin/python3  # Debian's, with python3-numpy (bench/loop_error_split.py)

json_value() {  # file dotted.key
  python3 -c "
import json, sys
value = json.load(open(sys.argv[1]))
for key in sys.argv[2].split('.'):
    value = value.get(key, {}) if isinstance(value, dict) else {}
print(value if value != {} else 'nan')" "$@"
}

results="$work/results.csv"
echo "sequence,loop_closing,run,ate_refined,ate_tracked,loops_closed,global_ba,seconds,load,keyframes_mm,final_at_keyframes_mm,final_at_others_mm" > "$results"
split_columns() {  # sequence out: keyframes, final at keyframes, final at the others (mm)
  "$python_numpy" "$root/bench/loop_error_split.py" "$1/groundtruth.txt" "$2" --json |
    python3 -c "import json, sys; f = json.load(sys.stdin)
print(','.join(f'{f[k]:.2f}' for k in ('keyframes', 'final_at_keyframes', 'final_at_others')))"
}
run_cell() {  # label sequence mode run [extra flags]
  local label="$1" seq="$2" mode="$3" r="$4"
  shift 4
  local out="$work/out_${label}_${mode}_$r"
  local load
  load="$(uptime | sed 's/.*load average: //' | cut -d, -f1)"
  "$cli" run --sequence "$seq" --out "$out" --loop-closing "$mode" "$@" ${run_flags[@]+"${run_flags[@]}"} \
    > "$out.log" 2>&1
  local stats="$out/stats.json" split="nan,nan,nan"
  # The split aligns rigidly (loop_error_split.py): meaningless for a monocular run.
  [[ "$label" == bonn_crowd_dev || "$sensor" == monocular ]] || split="$(split_columns "$seq" "$out")"
  echo "$label,$mode,$r,$(json_value "$stats" ate_refined.rmse),$(json_value "$stats" ate.rmse),$(json_value "$stats" loops.closed),$(json_value "$stats" loops.global_ba_applied),$(json_value "$stats" seconds),$load,$split" >> "$results"
  tail -n 1 "$results"
}

for loop in $loops; do
  seed="${loop%%:*}" turns="${loop#*:}"
  # Seed 1 at 1.5 turns keeps the folder name of the issue #4 measurements.
  label="synth_loop_s${seed}_t${turns}"
  sequence="$work/loop_900_${turns}turns"
  [[ "$seed" == 1 ]] || sequence="$work/loop_900_${turns}turns_seed$seed"
  if [[ ! -f "$sequence/groundtruth.txt" ]]; then
    "$cli" synth --out "$sequence" --frames 900 --bodies 0 --trajectory loop \
      --loop-turns "$turns" --seed "$seed" > "$sequence.synth.log"
  fi
  for r in $(seq 1 "$off_runs"); do run_cell "$label" "$sequence" off "$r" --dynamic off; done
  for r in $(seq 1 "$runs"); do run_cell "$label" "$sequence" on "$r" --dynamic off; done
done
if [[ "$bonn" == 1 && -d "$shared/data/bonn_crowd_dev" ]]; then
  for r in $(seq 1 "$runs"); do
    for mode in off on; do
      run_cell bonn_crowd_dev "$shared/data/bonn_crowd_dev" "$mode" "$r" --dynamic "$bonn_dynamic" \
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
print("\n| sequence | loop closing | runs | ATE refined median (m) | ATE tracked median (m) | keyframes (mm) | final at keyframes / others (mm) | loops closed | global BA applied |")
print("|---|---|---|---|---|---|---|---|---|")
medians = {}
median = lambda group, key: statistics.median(float(r[key]) for r in group)
for (sequence, mode), group in sorted(cells.items()):
    refined, tracked = median(group, "ate_refined"), median(group, "ate_tracked")
    keyframes = median(group, "keyframes_mm")
    at_keyframes, at_others = median(group, "final_at_keyframes_mm"), median(group, "final_at_others_mm")
    medians[(sequence, mode)] = (refined, tracked, keyframes)
    loops = "/".join(r["loops_closed"] for r in group)
    gba = "/".join(r["global_ba"] for r in group)
    print(f"| {sequence} | {mode} | {len(group)} | {refined:.4f} | {tracked:.4f} | {keyframes:.1f} | "
          f"{at_keyframes:.1f} / {at_others:.1f} | {loops} | {gba} |")
for sequence in sorted({s for s, _ in medians}):
    if (sequence, "on") in medians and (sequence, "off") in medians:
        on, off = medians[(sequence, "on")], medians[(sequence, "off")]
        print(f"{sequence}: on/off refined (trajectory_refined.txt) {on[0]:.4f}/{off[0]:.4f} = "
              f"{on[0] / off[0]:.2f}; tracked (trajectory.txt) {on[1]:.4f}/{off[1]:.4f} = "
              f"{on[1] / off[1]:.2f}; keyframes (keyframes.txt) {on[2]:.1f}/{off[2]:.1f} mm = "
              f"{on[2] / off[2]:.2f}")
PY
