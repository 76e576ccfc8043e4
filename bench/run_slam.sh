#!/usr/bin/env bash
# SLAM-core measurements for docs/benchmarks.md: ATE and per-frame timings of `pspslam run` on
#   - a synthetic static sequence (--bodies 0, 600 frames): accuracy of the core alone,
#   - a synthetic dynamic sequence (--bodies 3, 300 frames) and ../shared bonn_crowd_dev
#     (400 real frames, people from ~frame 220): runs end to end, ATE hurt by people.
# Bonn is run RUNS times: the reported tracking time is the median of the per-run medians.
# The machine is shared, so `uptime` is logged next to every run; timing.csv also has the
# tracking thread's CPU time, which waiting for a core does not inflate.
#
# usage: bench/run_slam.sh [BUILD_DIR (default build)] [WORK_DIR (default /tmp/pspslam_bench)]
#        RUNS=3 bench/run_slam.sh ...
# Every run is the SLAM core alone (`--dynamic off`) with the default deterministic feed (each
# frame waits for local mapping), so runs of one sequence give the same trajectory; the static
# sequence is still run RUNS times to show it.
set -euo pipefail
source "$(dirname "$0")/common.sh"
build="${1:-$root/build}"
work="${2:-/tmp/pspslam_bench}"
runs="${RUNS:-3}"
require_cli "$build"
mkdir -p "$work"

synth() {  # name frames bodies
  [[ -f "$work/$1/groundtruth.txt" ]] || "$cli" synth --out "$work/$1" --frames "$2" --bodies "$3" --seed 1
}

run() {  # label sequence out [extra flags]
  local label="$1" sequence="$2" out="$3"
  shift 3
  echo "== $label  ($(uptime | sed 's/.*load/load/'))"
  "$cli" run --sequence "$sequence" --out "$out" --dynamic off "$@" 2>/dev/null | grep -E "^(frames|speed|median|map|mapping|ATE)"
}

synth synth_static600 600 0
synth synth_dynamic300 300 3
for r in $(seq 1 "$runs"); do
  run "synthetic static, 600 frames, run $r" "$work/synth_static600" "$work/out_static600_$r"
done
run "synthetic dynamic (3 people), 300 frames" "$work/synth_dynamic300" "$work/out_dynamic300"
if [[ -d "$shared/data/bonn_crowd_dev" ]]; then
  for r in $(seq 1 "$runs"); do
    run "bonn_crowd_dev run $r" "$shared/data/bonn_crowd_dev" "$work/out_bonn_$r" --config "$root/config/bonn.yaml"
  done
  # Median over runs of the per-run median tracking time (wall and thread CPU), from timing.csv.
  for column in tracking_ms tracking_cpu_ms; do
    for r in $(seq 1 "$runs"); do
      awk -F, -v c="$column" 'NR==1{for(i=1;i<=NF;i++) if($i==c) k=i; next} {print $k}' \
        "$work/out_bonn_$r/timing.csv" | sort -g | awk '{v[NR]=$1} END{print v[int((NR+1)/2)]}'
    done | sort -g | awk -v c="$column" '{v[NR]=$1} END{print "bonn median " c " over runs: " v[int((NR+1)/2)]}'
  done
  echo "bonn max mapping queue per run: $(for r in $(seq 1 "$runs"); do
    awk -F, 'NR>1 && $11>m{m=$11} END{print m+0}' "$work/out_bonn_$r/timing.csv"; done | tr '\n' ' ')"
else
  echo "skipping bonn_crowd_dev: $shared/data/bonn_crowd_dev not found (set PSPSLAM_SHARED)"
fi
