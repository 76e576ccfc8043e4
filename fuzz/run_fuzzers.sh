#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan) and fuzzes each reader for a while.
#   fuzz/run_fuzzers.sh [SECONDS_PER_TARGET=600] [TARGET...]
# Fuzzing grows a working corpus in build-fuzz/corpus/<target>/ from the seeds in
# fuzz/corpus/<target>/; at the end the inputs that add coverage are merged into fuzz/corpus
# (commit them: CI replays them). Crashes land in build-fuzz/findings/<target>/. Prints one line per target: runs,
# executions, seconds, corpus size, crashes.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
shift || true
targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then
  targets=(trajectory sequence_lists config segmenter_metadata point_cloud_ply map_file vocabulary)
fi
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPSPSLAM_FUZZ=ON \
  > /dev/null
cmake --build build-fuzz -j "$(nproc)" --target "${targets[@]/#/fuzz_}"
for target in "${targets[@]}"; do
  findings=build-fuzz/findings/$target
  mkdir -p "$findings"
  log=build-fuzz/findings/$target.log
  # -timeout: an input that takes over 10 s is reported as a hang; -rss_limit_mb: as a memory blow-up.
  work=build-fuzz/corpus/$target
  mkdir -p "$work"
  build-fuzz/fuzz/fuzz_$target -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$findings/" -print_final_stats=1 "$work" "fuzz/corpus/$target" \
    > "$log" 2>&1 || true
  build-fuzz/fuzz/fuzz_$target -merge=1 "fuzz/corpus/$target" "$work" > "$log.merge" 2>&1 || true
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  crashes=$(find "$findings" -type f | wc -l)
  echo "$target: $runs executions in ${seconds} s, corpus $(ls "fuzz/corpus/$target" | wc -l) files, $crashes findings"
done
