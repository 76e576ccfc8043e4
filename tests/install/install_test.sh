#!/usr/bin/env bash
# cmake --install, then move the installed tree elsewhere (relocatable: nothing may point back
# into the source or build tree) and check that
#  1. the installed program runs and finds its shipped model and vocabulary inside the moved tree;
#  2. a consumer project builds against it with find_package(pspslam) and tracks a sequence
#     through the public API with the shipped PSPNet masking people.
#   install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
source=$2
work=$(mktemp -d /tmp/pspslam_install_test.XXXXXX)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/first" > "$work/install.log"
mv "$work/first" "$work/moved"
cli=$work/moved/bin/pspslam
"$cli" --version | grep -q '^pspslam [0-9.]* (git ' || { echo "FAIL: --version"; exit 1; }
"$cli" -q synth --out "$work/seq" --frames 30 --bodies 2 --seed 7 > /dev/null
# From a folder outside both trees, with the default model and vocabulary.
(cd "$work" && "$cli" -q run --sequence seq --out out --loop-closing auto) > "$work/run.log" 2>&1
grep -q "dynamic:      full (model $work/moved/share/pspslam/models/pspnet/pspnet.yaml)" \
  "$work/run.log" || { echo "FAIL: the default model is not the installed one"; cat "$work/run.log"; exit 1; }
grep -q "loop closing: on" "$work/run.log" ||
  { echo "FAIL: the installed vocabulary was not found (loop closing off)"; cat "$work/run.log"; exit 1; }
# The installed viewer serves its page and three.js from share/pspslam/web (plain bash /dev/tcp:
# no HTTP client is among the dependencies).
"$cli" view "$work/out" --viewer 0 > "$work/view.log" 2>&1 &
view_pid=$!
for _ in $(seq 600); do grep -q 'viewer: http' "$work/view.log" && break; sleep 0.1; done
port=$(sed -n 's|^viewer: http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$work/view.log")
for asset in / /scene.js /live.html /live.js /vendor/three/build/three.module.js \
             /vendor/three/examples/jsm/controls/OrbitControls.js; do
  exec 3<> "/dev/tcp/127.0.0.1/$port"
  printf 'GET %s HTTP/1.0\r\n\r\n' "$asset" >&3
  status=$(head -n 1 <&3)
  exec 3>&-
  [[ $status == *" 200 "* ]] ||
    { echo "FAIL: installed viewer: $asset: $status"; cat "$work/view.log"; kill -INT $view_pid; exit 1; }
done
kill -INT $view_pid
wait $view_pid || { echo "FAIL: the viewer did not stop cleanly"; cat "$work/view.log"; exit 1; }
if grep -rq "$source" "$work/moved/lib/cmake"; then
  echo "FAIL: the package config points into the source tree"; exit 1
fi
cmake -S "$source/tests/install/consumer" -B "$work/consumer" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/moved" > "$work/consumer.log" 2>&1 ||
  { echo "FAIL: consumer configure"; cat "$work/consumer.log"; exit 1; }
cmake --build "$work/consumer" -j 2 >> "$work/consumer.log" 2>&1 ||
  { echo "FAIL: consumer build"; tail -30 "$work/consumer.log"; exit 1; }
line=$("$work/consumer/consumer" "$work/seq")
echo "$line"
read -r _ frames _ tracked _ masked _ model <<< "$line"
[[ $frames -eq 30 && $tracked -ge 28 && $masked -ge 20 ]] ||
  { echo "FAIL: consumer tracked $tracked of $frames frames, $masked with a mask"; exit 1; }
[[ $model == "$work/moved/share/pspslam/models/pspnet/pspnet.yaml" ]] ||
  { echo "FAIL: consumer model $model"; exit 1; }
echo "install test passed"
