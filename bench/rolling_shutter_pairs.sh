#!/usr/bin/env bash
# Rolling shutter on bonn_crowd_dev, every mode and sensor, paired in one invocation: the preset
# as it is (camera.rolling_shutter_readout: 0.03) against the same preset with the key removed
# (a global shutter, the behaviour before it existed). One deterministic run per cell; prints
# ATE RMSE (mm) of trajectory.txt (online) and trajectory_refined.txt (final), the tracked
# frames and the median tracking time per frame.
#
# usage: [BUILD=build] [WORK=/tmp/pspslam_rs_pairs] [MODES="off semantic geometry full exhaustive"]
#        [SENSORS="rgbd monocular"] bench/rolling_shutter_pairs.sh
set -euo pipefail
source "$(dirname "$0")/common.sh"
build="${BUILD:-$root/build}"
work="${WORK:-/tmp/pspslam_rs_pairs}"
modes="${MODES:-off semantic geometry full exhaustive}"
sensors="${SENSORS:-rgbd monocular}"
require_cli "$build"
shared="${PSPSLAM_SHARED:-$root/../shared}"
dev="$shared/data/bonn_crowd_dev"
[[ -d "$dev" ]] || { echo "error: $dev not found (set PSPSLAM_SHARED)" >&2; exit 1; }
mkdir -p "$work"
cp "$root/config/bonn.yaml" "$work/readout.yaml"
sed '/rolling_shutter_readout/d' "$root/config/bonn.yaml" > "$work/global.yaml"
ate() {  # FILE -> "rmse_mm (count)"
  "$cli" -q eval --gt "$dev/groundtruth.txt" --est "$1" --json 2>/dev/null |
    "${PYTHON:-python3}" -c 'import json, sys
e = json.load(sys.stdin)["ate"]["error_m"]
print("%.1f (%d)" % (e["rmse"] * 1e3, e["count"]))' || echo "-"
}
median_tracking_ms() {
  "${PYTHON:-python3}" -c 'import csv,statistics,sys; r=[float(x["tracking_ms"]) for x in csv.DictReader(open(sys.argv[1])) if x["state"]=="ok"]; print(f"{statistics.median(r):.2f}")' "$1"
}
echo "| sensor | mode | global shutter: online / final (tracked) | readout 0.03 s: online / final (tracked) | tracking ms (median) global / readout |"
echo "|---|---|---|---|---|"
for sensor in $sensors; do
  for mode in $modes; do
    for variant in global readout; do
      out="$work/$sensor-$mode-$variant"
      [[ -f "$out/stats.json" ]] ||
        "$cli" -q run --sequence "$dev" --config "$work/$variant.yaml" --sensor "$sensor" \
          --dynamic "$mode" --out "$out" >"$out.log" 2>&1 || true
    done
    row="| $sensor | $mode |"
    for variant in global readout; do
      out="$work/$sensor-$mode-$variant"
      row="$row $(ate "$out/trajectory.txt") / $(ate "$out/trajectory_refined.txt") |"
    done
    row="$row $(median_tracking_ms "$work/$sensor-$mode-global/timing.csv") / $(median_tracking_ms "$work/$sensor-$mode-readout/timing.csv") |"
    echo "$row"
  done
done
