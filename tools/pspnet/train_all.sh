#!/usr/bin/env bash
# Reproduces models/pspnet/ from scratch on CPU (about 45-60 min on 2 cores):
#   split + teacher soft targets -> training -> ONNX export (384x288 shipped, 288x192 extra).
# Uses Debian's python3 (torch 1.13, onnx, opencv 4.6) and ../shared (PSPSLAM_SHARED).
# Environment: EPOCHS (default 2), MAX_MINUTES (default 45).
# OpenMP threads sleep instead of spinning: the machine is shared and oversubscribed.
export OMP_WAIT_POLICY=PASSIVE
set -euo pipefail
cd "$(dirname "$0")"
PY=/usr/bin/python3
mkdir -p work
nice -n 10 "$PY" prepare.py
nice -n 10 "$PY" train.py --epochs "${EPOCHS:-2}" --max-minutes "${MAX_MINUTES:-45}"
nice -n 10 "$PY" export.py --width 384 --height 288 --yaml pspnet.yaml --golden
nice -n 10 "$PY" export.py --width 288 --height 192 --yaml pspnet_288x192.yaml
"$PY" evaluate.py ../../models/pspnet/pspnet.yaml ../../models/pspnet/pspnet_288x192.yaml
echo "done: models/pspnet/ updated; C++ numbers: build bench_segmentation and run it"
