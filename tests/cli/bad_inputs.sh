#!/usr/bin/env bash
# Tries every bad input we know of, as a user would meet it, and prints a Markdown table row per
# case: what was given, the exit status, and the first line of the message. The table in
# docs/reliability.md is this script's output.
#   tests/cli/bad_inputs.sh [PSPSLAM_BINARY]   (default build/apps/pspslam; a ctest)
# Each case names the exit status it must give (2: bad input, 3: no map could start, 0: a
# warning only); any other status is marked "WRONG" in the last column, and the script exits 1.
set -uo pipefail
cd "$(dirname "$0")/../.."
cli=$(realpath "${1:-build/apps/pspslam}")
models=$PWD/models
work=$(mktemp -d /tmp/pspslam_bad_inputs.XXXXXX)
trap 'rm -rf "$work"' EXIT
cd "$work"

# Fixtures: a short synthetic sequence and variants broken one way each.
"$cli" -q synth --out seq --frames 12 --bodies 1 --seed 3 > /dev/null
"$cli" -q run --sequence seq --out good --dynamic off --loop-closing off --save-map good.map > /dev/null 2>&1
copy() { rm -rf "$1" && cp -r seq "$1"; }
copy garbage_line && sed -i '5s/.*/hello world again/' garbage_line/rgb.txt
copy nan_stamp && sed -i '5s/^[0-9.]*/nan/' nan_stamp/rgb.txt
copy one_field && sed -i '5s/ .*//' one_field/depth.txt
copy no_lists && rm no_lists/rgb.txt no_lists/depth.txt
copy depth8 && for f in depth8/depth/*.png; do python3 -c "import sys,zlib,struct
w,h=640,480
raw=b''.join(b'\x00'+bytes(w) for _ in range(h))
def chunk(t,d): return struct.pack('>I',len(d))+t+d+struct.pack('>I',zlib.crc32(t+d)&0xffffffff)
open(sys.argv[1],'wb').write(b'\x89PNG\r\n\x1a\n'+chunk(b'IHDR',struct.pack('>IIBBBBB',w,h,8,0,0,0,0))+chunk(b'IDAT',zlib.compress(raw))+chunk(b'IEND',b''))" "$f"; done
copy depth_rgb && for f in depth_rgb/depth/*.png; do cp "$(ls seq/rgb/*.png | head -1)" "$f"; done
copy tiny_colour && for f in tiny_colour/rgb/*.png; do head -c 67 /dev/null > /dev/null; python3 -c "import sys,zlib,struct
raw=b'\x00'+bytes(3)
def chunk(t,d): return struct.pack('>I',len(d))+t+d+struct.pack('>I',zlib.crc32(t+d)&0xffffffff)
open(sys.argv[1],'wb').write(b'\x89PNG\r\n\x1a\n'+chunk(b'IHDR',struct.pack('>IIBBBBB',1,1,8,2,0,0,0))+chunk(b'IDAT',zlib.compress(raw))+chunk(b'IEND',b''))" "$f"; done
copy corrupt_colour && for f in corrupt_colour/rgb/*.png; do echo "not a png" > "$f"; done
copy missing_images && rm missing_images/rgb/$(ls missing_images/rgb | sed -n 3p)
copy no_config && rm no_config/config.yaml
copy bad_gt && sed -i '3s/.*/1.0 2.0 3.0/' bad_gt/groundtruth.txt
copy no_depth && python3 - no_depth <<'PY'
import sys,zlib,struct,glob
w,h=640,480
raw=b''.join(b'\x00'+bytes(2*w) for _ in range(h))
def chunk(t,d): return struct.pack('>I',len(d))+t+d+struct.pack('>I',zlib.crc32(t+d)&0xffffffff)
png=b'\x89PNG\r\n\x1a\n'+chunk(b'IHDR',struct.pack('>IIBBBBB',w,h,16,0,0,0,0))+chunk(b'IDAT',zlib.compress(raw))+chunk(b'IEND',b'')
for f in glob.glob(sys.argv[1]+'/depth/*.png'): open(f,'wb').write(png)
PY
sed 's/width:/widht:/' seq/config.yaml > typo.yaml
grep -v ' fx:' seq/config.yaml > no_fx.yaml
head -c 400 /dev/urandom > binary.yaml
echo "camera: 5" > not_mapping.yaml
sed 's/fx: .*/fx: -525/' seq/config.yaml > negative_fx.yaml
echo "file" > a_file
head -3 seq/groundtruth.txt | tail -1 > one_pose.txt
printf '1.0 0 0 0 0 0 1\n' > seven_fields.txt
: > empty.txt
awk '!/^#/ {$1 = sprintf("%.6f", $1 + 5000); print}' seq/groundtruth.txt > shifted.txt
echo "not a vocabulary" > garbage.pspvoc
head -c 30 "$models/vocabulary/orb_k10_l5.pspvoc" > truncated.pspvoc
echo "not a map" > garbage.map
head -c 2000 good.map > truncated.map
"$cli" -q synth --out other_cam --frames 2 --bodies 0 --seed 3 > /dev/null
sed -i 's/fx: .*/fx: 500/' other_cam/config.yaml
sed "s|onnx: .*|onnx: missing.onnx|" "$models/pspnet/pspnet.yaml" > missing_onnx.yaml
echo "garbage" > garbage.onnx
sed "s|onnx: .*|onnx: garbage.onnx|" "$models/pspnet/pspnet.yaml" > garbage_onnx.yaml
mkdir -p images_empty

failures=0
row() {  # row "what was given" EXPECTED_STATUS -- command...
  local what=$1 expected=$2
  shift 3
  local output status
  output=$(timeout 300 "$@" 2>&1 > /dev/null)
  status=$?
  local message
  output=$(printf '%s\n' "$output" | LC_ALL=C tr -c '[:print:]\n' '?')
  message=$(printf '%s\n' "$output" | grep -m1 -E '^(error|warning|internal error)' ||
            printf '%s\n' "$output" | head -1)
  message=${message//$work\//}
  message=${message//|/\\|}
  local verdict=ok
  if [[ $status -ne $expected ]]; then verdict="WRONG (expected $expected)"; failures=$((failures + 1)); fi
  printf '| %s | %s | `%s` | %s |\n' "$what" "$status" "${message:0:220}" "$verdict"
}
R="$cli run --out out --loop-closing off"
L="$cli run --out out --dynamic off --loop-closing on"
echo "| bad input | exit | message (first line) | verdict |"
echo "|---|---|---|---|"
row "no command" 2 -- "$cli"
row "unknown command \`pspslam fly\`" 2 -- "$cli" fly
row "\`run\` without --sequence" 2 -- "$cli" run
row "--dynamic foo" 2 -- $R --sequence seq --dynamic foo
row "--mask-margin 1000000000" 2 -- $R --sequence seq --mask-margin 1000000000
row "--mask-margin -1" 2 -- $R --sequence seq --mask-margin -1
row "--keyframe-ratio 0" 2 -- $R --sequence seq --keyframe-ratio 0
row "--keyframe-ratio abc" 2 -- $R --sequence seq --keyframe-ratio abc
row "--max-frames -3" 2 -- $R --sequence seq --max-frames -3
row "--max-frames 1e3" 2 -- $R --sequence seq --max-frames 1e3
row "--start-frame past the end" 2 -- $R --sequence seq --start-frame 12
row "--blackout 3 (no count)" 2 -- $R --sequence seq --blackout 3
row "--blackout 5:0" 2 -- $R --sequence seq --blackout 5:0
row "--loop-closing maybe" 2 -- $R --sequence seq --loop-closing maybe
row "--cull-hits 0" 2 -- $R --sequence seq --cull-hits 0
row "--localization without --load-map" 2 -- $R --sequence seq --localization
row "--load-map of a missing file" 2 -- $R --sequence seq --load-map none.map
row "mistyped flag --realtme" 2 -- $R --sequence seq --realtme
row "flag without its value (--out at the end)" 2 -- "$cli" run --sequence seq --out
row "--out below a regular file" 2 -- "$cli" run --sequence seq --out a_file/run
row "--out is a regular file" 2 -- "$cli" run --sequence seq --out a_file
row "--save-map names a folder" 2 -- $R --sequence seq --save-map seq
row "--export-map below a regular file" 2 -- $R --sequence seq --export-map a_file/map.ply
row "--export-dense below a regular file" 2 -- $R --sequence seq --export-dense a_file/dense.ply
row "--export-octomap below a regular file" 2 -- $R --sequence seq --export-octomap a_file/map.bt
row "--export-grid below a regular file" 2 -- $R --sequence seq --export-grid a_file/grid.yaml
row "--occupancy-resolution 0" 2 -- $R --sequence seq --occupancy --occupancy-resolution 0
row "--occupancy-resolution -0.05" 2 -- $R --sequence seq --export-grid g.yaml --occupancy-resolution -0.05
row "height band upside down" 2 -- $R --sequence seq --export-grid g.yaml --grid-min-height 1.2 --grid-max-height 0.3
row "--grid-floor low" 2 -- $R --sequence seq --export-grid g.yaml --grid-floor low
row "--occupancy-truth without static.txt" 2 -- $R --sequence seq --occupancy-truth seq
row "--save-masks below a regular file" 2 -- $R --sequence seq --save-masks a_file/masks
row "--save-overlays is a regular file" 2 -- $R --sequence seq --save-overlays a_file
row "eval --title without its value" 2 -- "$cli" eval --gt seq/groundtruth.txt --est good/trajectory.txt --title
row "--camera webcam (unknown driver)" 2 -- "$cli" run --camera webcam --out out
row "--camera freenect with no Kinect attached" 2 -- "$cli" run --camera freenect --out out
row "record --camera freenect:abc" 2 -- "$cli" record --camera freenect:abc --out rec
row "--log-level chatty" 2 -- "$cli" --log-level chatty run --sequence seq
row "sequence folder missing" 2 -- $R --sequence nowhere
row "no rgb.txt / depth.txt" 2 -- $R --sequence no_lists
row "garbage line in rgb.txt" 2 -- $R --sequence garbage_line
row "NaN time stamp in rgb.txt" 2 -- $R --sequence nan_stamp
row "one field on a depth.txt line" 2 -- $R --sequence one_field
row "8-bit depth images" 2 -- $R --sequence depth8
row "3-channel depth images" 2 -- $R --sequence depth_rgb
row "1x1 colour images" 2 -- $R --sequence tiny_colour
row "colour file that is not an image" 2 -- $R --sequence corrupt_colour
row "one colour file missing (warning, run goes on: must exit 0)" 0 -- $R --sequence missing_images
row "no config.yaml and no --config" 2 -- $R --sequence no_config
row "config key typo widht" 2 -- $R --sequence seq --config typo.yaml
row "config without fx" 2 -- $R --sequence seq --config no_fx.yaml
row "config of random bytes" 2 -- $R --sequence seq --config binary.yaml
row "config whose camera is not a mapping" 2 -- $R --sequence seq --config not_mapping.yaml
row "config with negative fx" 2 -- $R --sequence seq --config negative_fx.yaml
row "--config of a missing file" 2 -- $R --sequence seq --config none.yaml
row "malformed groundtruth.txt line" 2 -- $R --sequence bad_gt
row "depth images without a reading (no map can start)" 3 -- $R --sequence no_depth --dynamic off
row "--vocabulary of garbage" 2 -- $L --sequence seq --vocabulary garbage.pspvoc
row "--vocabulary truncated" 2 -- $L --sequence seq --vocabulary truncated.pspvoc
row "--vocabulary missing (loop closing on)" 2 -- $L --sequence seq --vocabulary none.pspvoc
row "--model missing" 2 -- $R --sequence seq --dynamic full --model none.yaml
row "--model whose ONNX is missing" 2 -- $R --sequence seq --dynamic full --model missing_onnx.yaml
row "--model whose ONNX is garbage" 2 -- $R --sequence seq --dynamic full --model garbage_onnx.yaml
row "--load-map of garbage" 2 -- $R --sequence seq --dynamic off --load-map garbage.map
row "--load-map truncated" 2 -- $R --sequence seq --dynamic off --load-map truncated.map
row "--load-map made with another camera" 2 -- $R --sequence other_cam --dynamic off --load-map good.map
row "\`eval\` without --gt" 2 -- "$cli" eval --est one_pose.txt
row "eval --rpe-unit m" 2 -- "$cli" eval --gt seq/groundtruth.txt --est good/trajectory.txt --rpe-unit m
row "eval --max-dt fast" 2 -- "$cli" eval --gt seq/groundtruth.txt --est good/trajectory.txt --max-dt fast
row "eval --max-dt 0" 2 -- "$cli" eval --gt seq/groundtruth.txt --est good/trajectory.txt --max-dt 0
row "eval --plots (typo of --plot)" 2 -- "$cli" eval --gt seq/groundtruth.txt --est good/trajectory.txt --plots p
row "eval: ground truth missing" 2 -- "$cli" eval --gt none.txt --est good/trajectory.txt
row "eval: estimate line of 7 fields" 2 -- "$cli" eval --gt seq/groundtruth.txt --est seven_fields.txt
row "eval: empty estimate" 2 -- "$cli" eval --gt seq/groundtruth.txt --est empty.txt
row "eval: no time stamps in common" 2 -- "$cli" eval --gt seq/groundtruth.txt --est shifted.txt
row "eval --plot below a regular file" 2 -- "$cli" eval --gt seq/groundtruth.txt --est good/trajectory.txt --plot a_file/p
row "synth --frames 0" 2 -- "$cli" synth --out s --frames 0
row "synth --bodies 1000" 2 -- "$cli" synth --out s --bodies 1000
row "synth --trajectory circle" 2 -- "$cli" synth --out s --trajectory circle
row "synth --depth-noise maybe" 2 -- "$cli" synth --out s --depth-noise maybe
row "synth --seed -1" 2 -- "$cli" synth --out s --seed -1
row "synth --out below a regular file" 2 -- "$cli" synth --out a_file/s --frames 1
row "segment --step 0" 2 -- "$cli" segment --images images_empty --out o --step 0
row "segment --images not a folder" 2 -- "$cli" segment --images a_file --out o
row "segment: folder without images" 2 -- "$cli" segment --images images_empty --out o
row "segment --threads 0" 2 -- "$cli" segment --images images_empty --out o --threads 0
row "\`vocab\` without sub-command" 2 -- "$cli" vocab
row "vocab train --synthetic-seed 5" 2 -- "$cli" vocab train --synthetic-frames 1 --synthetic-seed 5 --out v
row "vocab train --k 1" 2 -- "$cli" vocab train --synthetic-frames 1 --k 1 --out v
row "vocab train without data" 2 -- "$cli" vocab train --out v
row "vocab info of a missing file" 2 -- "$cli" vocab info --vocabulary none.pspvoc
echo
echo "$failures wrong"
[[ $failures -eq 0 ]]
