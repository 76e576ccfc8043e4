#!/usr/bin/env bash
# PSPNet-SLAM dynamic modes benchmark (issue #7): sequences x modes x RUNS runs of `pspslam run`,
# then bench/aggregate_modes.py collects ATE / RPE / per-thread times / fps into
# bench/results/modes.json and writes bench/results/modes.md (the section for docs/benchmarks.md)
# and the plots docs/modes_*.png / .svg (trajectory overlays via `pspslam eval --plot`).
#
# Sequences: synthetic dynamic (`pspslam synth --frames 300 --bodies 3 --seed 1`), its static twin
# (--bodies 0), ../shared/data/bonn_crowd_dev (when present; $PSPSLAM_SHARED overrides ../shared)
# and any TUM folder given as DIR=PRESET (PRESET = config YAML for it).
#
# usage: bench/run_modes.sh [DIR=PRESET ...]
#   RUNS=5 MODES="off semantic geometry full exhaustive" SEQUENCES="synth_dynamic synth_static bonn"
#   BUILD=build WORK=/tmp/pspslam_modes REALTIME=0 bench/run_modes.sh
# Existing runs (OUT/stats.json present) are kept, so an interrupted benchmark resumes.
set -euo pipefail
source "$(dirname "$0")/common.sh"
build="${BUILD:-$root/build}"
work="${WORK:-/tmp/pspslam_modes}"
runs="${RUNS:-5}"
modes="${MODES:-off semantic geometry full exhaustive}"
sequences="${SEQUENCES:-synth_dynamic synth_static bonn}"
require_cli "$build"
mkdir -p "$work" "$root/bench/results"

declare -A seq_dir seq_config
if [[ " $sequences " == *" synth_dynamic "* ]]; then
  [[ -f "$work/synth_dynamic/groundtruth.txt" ]] ||
    "$cli" synth --out "$work/synth_dynamic" --frames 300 --bodies 3 --seed 1 >/dev/null
  seq_dir[synth_dynamic]="$work/synth_dynamic"
fi
if [[ " $sequences " == *" synth_static "* ]]; then
  [[ -f "$work/synth_static/groundtruth.txt" ]] ||
    "$cli" synth --out "$work/synth_static" --frames 300 --bodies 0 --seed 1 >/dev/null
  seq_dir[synth_static]="$work/synth_static"
fi
if [[ " $sequences " == *" bonn "* && -d "$shared/data/bonn_crowd_dev" ]]; then
  seq_dir[bonn_crowd_dev]="$shared/data/bonn_crowd_dev"
  seq_config[bonn_crowd_dev]="$root/config/bonn.yaml"
fi
for arg in "$@"; do
  dir="${arg%%=*}"
  preset="${arg#*=}"
  [[ -d "$dir" && -f "$preset" ]] || { echo "error: expected DIR=PRESET, got '$arg'" >&2; exit 2; }
  name="$(basename "$dir")"
  seq_dir[$name]="$dir"
  seq_config[$name]="$preset"
done

extra=()
[[ "${REALTIME:-0}" == 1 ]] && extra+=(--realtime)
# Run-major, then mode-major: a benchmark cut short still has every sequence in the first modes.
for r in $(seq 1 "$runs"); do
  for mode in $modes; do
    for name in "${!seq_dir[@]}"; do
      out="$work/runs/$name/$mode/run$r"
      [[ -f "$out/stats.json" ]] && continue
      config=()
      [[ -n "${seq_config[$name]:-}" ]] && config=(--config "${seq_config[$name]}")
      echo "== $name $mode run $r  ($(date -u +%H:%M:%S), $(uptime | sed 's/.*load/load/'))"
      mkdir -p "$out"
      "$cli" run --sequence "${seq_dir[$name]}" "${config[@]}" --dynamic "$mode" --out "$out" \
        "${extra[@]}" >"$out/run.log" 2>"$out/stderr.log" || echo "   exit status $?"
      grep -E "^(ATE trajectory.txt|speed)" "$out/run.log" || true
      if [[ -f "${seq_dir[$name]}/groundtruth.txt" ]]; then
        "$cli" eval --gt "${seq_dir[$name]}/groundtruth.txt" --est "$out/trajectory.txt" --json \
          >"$out/eval.json" 2>/dev/null || true
      fi
    done
  done
done
python3 "$root/bench/aggregate_modes.py" --work "$work" --cli "$cli" --results "$root/bench/results" \
  --docs "$root/docs" --sequence-dirs "$(for n in "${!seq_dir[@]}"; do printf '%s=%s ' "$n" "${seq_dir[$n]}"; done)"
