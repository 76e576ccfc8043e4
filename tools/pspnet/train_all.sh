#!/usr/bin/env bash
# Reproduces models/pspnet/ from scratch (CPU by default; a CUDA GPU is used when present):
#   split + teacher-ensemble soft targets (DeepLab v3 MNv2 1.0 + ESPNetv2, prepare.py) ->
#   40 epochs at 384x288 (arch os16_decoder) -> ONNX export (384x288 shipped, 288x192 and
#   480x384 with the same weights for the size/IoU trade-off) -> cv2.dnn IoU.
# Uses Debian's python3 (torch 1.13, onnx, opencv 4.6) and ../shared (PSPSLAM_SHARED).
# Environment: EPOCHS (default 40: the shipped model), MAX_MINUTES (wall-clock cap of the
# training, default 150: it stops after the epoch that passes it and ships that epoch).
# On the shared 2-core machine (MODEL_CARD.md "Training"): prepare ~18 min, training ~65 s per
# epoch when the machine is otherwise idle (~75 s beside a build), so about 75 min in all.
# OpenMP threads sleep instead of spinning: the machine is shared and oversubscribed.
export OMP_WAIT_POLICY=PASSIVE
set -euo pipefail
cd "$(dirname "$0")"
PY=/usr/bin/python3
mkdir -p work
nice -n 19 "$PY" prepare.py
nice -n 19 "$PY" train.py --arch os16_decoder --last-dilation 2 --input-width 384 \
  --input-height 288 --epochs "${EPOCHS:-40}" --max-minutes "${MAX_MINUTES:-150}" --batch 8 \
  --gt-weight 2 --iou-weight 1 --threads 2 --eval-every 2 --initial-eval
nice -n 19 "$PY" export.py --width 384 --height 288 --yaml pspnet.yaml --golden
nice -n 19 "$PY" export.py --width 288 --height 192 --yaml pspnet_288x192.yaml
nice -n 19 "$PY" export.py --width 480 --height 384 --yaml pspnet_480x384.yaml
"$PY" evaluate.py ../../models/pspnet/pspnet.yaml ../../models/pspnet/pspnet_288x192.yaml \
  ../../models/pspnet/pspnet_480x384.yaml
echo "done: models/pspnet/ updated; C++ numbers: build bench_segmentation and run it"
