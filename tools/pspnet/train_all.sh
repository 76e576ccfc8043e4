#!/usr/bin/env bash
# Reproduces models/pspnet/ from scratch (CPU by default; a CUDA GPU is used when present):
#   split + teacher soft targets -> training at 288x240 -> ONNX export (288x240 shipped,
#   384x288 and 192x144 with the same weights for the size/IoU trade-off) -> cv2.dnn IoU.
# Uses Debian's python3 (torch 1.13, onnx, opencv 4.6) and ../shared (PSPSLAM_SHARED).
# Environment: EPOCHS (default: the epochs of the shipped model), MAX_MINUTES (wall-clock cap,
# default 100: the run stops after the epoch that passes it and ships that epoch).
# On the shared 2-core machine: about 5-6 min per epoch at nice 19 (see MODEL_CARD.md).
# OpenMP threads sleep instead of spinning: the machine is shared and oversubscribed.
export OMP_WAIT_POLICY=PASSIVE
set -euo pipefail
cd "$(dirname "$0")"
PY=/usr/bin/python3
mkdir -p work
nice -n 19 "$PY" prepare.py
nice -n 19 "$PY" train.py --input-width 288 --input-height 240 --last-dilation 2 \
  --epochs "${EPOCHS:-13}" --max-minutes "${MAX_MINUTES:-100}" --batch 8 \
  --gt-weight 2 --iou-weight 1 --threads 2 --initial-eval
nice -n 19 "$PY" export.py --width 288 --height 240 --yaml pspnet.yaml --golden
nice -n 19 "$PY" export.py --width 384 --height 288 --yaml pspnet_384x288.yaml
nice -n 19 "$PY" export.py --width 192 --height 144 --yaml pspnet_192x144.yaml
"$PY" evaluate.py ../../models/pspnet/pspnet.yaml ../../models/pspnet/pspnet_384x288.yaml \
  ../../models/pspnet/pspnet_192x144.yaml
echo "done: models/pspnet/ updated; C++ numbers: build bench_segmentation and run it"
