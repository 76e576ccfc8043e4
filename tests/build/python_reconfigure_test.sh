#!/usr/bin/env bash
# The README's order, `make demo` then `make test`, reuses one build folder: the first configure
# may run before pybind11 and numpy are installed, and the second must then build the Python
# module. Checked on a scratch folder with configure only (no compilation):
#  1. configured as `make demo` does while pybind11 is missing: no module;
#  2. reconfigured as `make test` does once it is there: the module and its tests are in;
#  3. a folder cached by the former BOOL option (OFF, never asked for) builds it too;
#  4. -DPSPSLAM_PYTHON=OFF, asked for, stays off across a reconfigure.
#   python_reconfigure_test.sh SOURCE_DIR
set -euo pipefail
source=$1
work=$(mktemp -d /tmp/pspslam_reconfigure_test.XXXXXX)
trap 'rm -rf "$work"' EXIT
build=$work/build
configure() {
  cmake -S "$source" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" > "$work/configure.log" 2>&1 ||
    { echo "FAIL: configure $*"; cat "$work/configure.log"; exit 1; }
}
expect() {  # expect ON|OFF WHAT
  grep -q "Python module (PSPSLAM_PYTHON=.*): $1\$" "$work/configure.log" ||
    { echo "FAIL: $2: expected the module $1"; grep "Python module" "$work/configure.log"; exit 1; }
  local has_target=OFF
  if grep -q "pspslam_python" "$build/build.ninja"; then has_target=ON; fi
  [[ $has_target == "$1" ]] || { echo "FAIL: $2: pspslam_python target $has_target"; exit 1; }
}

configure -DBUILD_TESTING=OFF -DCMAKE_DISABLE_FIND_PACKAGE_pybind11=ON
expect OFF "make demo without pybind11"
configure -DBUILD_TESTING=ON -UCMAKE_DISABLE_FIND_PACKAGE_pybind11
expect ON "make test after pybind11 was installed"
grep -q "python.pytest" "$build/CTestTestfile.cmake" "$build"/python/CTestTestfile.cmake ||
  { echo "FAIL: python.pytest is not a test"; exit 1; }

# The former entry: a BOOL with its own help line (the current help may wrap over several lines).
python3 - "$build/CMakeCache.txt" <<'PY'
import re, sys
cache = open(sys.argv[1]).read()
cache = re.sub(r"(//[^\n]*\n)+PSPSLAM_PYTHON:STRING=[^\n]*\n",
               "//build the Python module (import pspslam)\nPSPSLAM_PYTHON:BOOL=OFF\n", cache)
open(sys.argv[1], "w").write(cache)
PY
grep -q "^PSPSLAM_PYTHON:BOOL=OFF" "$build/CMakeCache.txt" || { echo "FAIL: cache not rewritten"; exit 1; }
configure -DBUILD_TESTING=ON
expect ON "a folder cached by the former option"

configure -DBUILD_TESTING=ON -DPSPSLAM_PYTHON=OFF
expect OFF "asked OFF"
configure -DBUILD_TESTING=ON
expect OFF "asked OFF, reconfigured"
echo "python reconfigure test passed"
