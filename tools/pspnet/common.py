"""Paths, preprocessing and metrics shared by the PSPNet tools."""

import json
import os
import random
from pathlib import Path

import cv2
import numpy as np

REPO = Path(__file__).resolve().parents[2]
SHARED = Path(os.environ.get("PSPSLAM_SHARED", REPO.parent / "shared"))
WORK = REPO / "tools" / "pspnet" / "work"
MODEL_DIR = REPO / "models" / "pspnet"
SPLIT_FILE = MODEL_DIR / "human_seg_split.json"

VOC_CLASSES = [
    "background", "aeroplane", "bicycle", "bird", "boat", "bottle", "bus", "car", "cat",
    "chair", "cow", "diningtable", "dog", "horse", "motorbike", "person", "pottedplant",
    "sheep", "sofa", "train", "tvmonitor"]
PERSON = 15
DYNAMIC_CLASSES = ["person", "bird", "cat", "cow", "dog", "horse", "sheep", "aeroplane",
                   "bicycle", "boat", "bus", "car", "motorbike", "train"]

# Our network's input normalisation (that of the DeepLab weights it starts from):
# RGB, (pixel - 128) / 128.
MEAN = (128.0, 128.0, 128.0)
STD = (128.0, 128.0, 128.0)

# The teachers as the shared README describes them (normalisation in pixel units).
TEACHERS = {
    "deeplabv3_mnv2_pascal": dict(onnx="deeplabv3_mnv2_pascal.onnx", width=513, height=513,
                                  mean=(128.0, 128.0, 128.0), std=(128.0, 128.0, 128.0)),
    "deeplabv3_mnv2_dm05_pascal": dict(onnx="deeplabv3_mnv2_dm05_pascal.onnx", width=513,
                                       height=513, mean=(128.0, 128.0, 128.0),
                                       std=(128.0, 128.0, 128.0)),
    "espnetv2_s2.0_pascal_384x384": dict(onnx="espnetv2_s2.0_pascal_384x384.onnx", width=384,
                                         height=384, mean=(123.675, 116.28, 103.53),
                                         std=(58.395, 57.12, 57.375)),
}


def to_blob(bgr, width, height, mean=MEAN, std=STD):
    """BGR uint8 image -> 1x3xHxW float32 RGB blob, stretched to width x height.

    Same arithmetic as OnnxSegmenter in C++ (bilinear resize, then per-channel
    (p - mean) / std)."""
    if bgr.shape[1] != width or bgr.shape[0] != height:
        bgr = cv2.resize(bgr, (width, height), interpolation=cv2.INTER_LINEAR)
    rgb = bgr[:, :, ::-1].astype(np.float32)
    rgb = (rgb - np.float32(mean)) / np.float32(std)
    return np.ascontiguousarray(rgb.transpose(2, 0, 1)[None])


def human_seg_ids():
    root = SHARED / "data" / "human_seg" / "images"
    return sorted(int(p.stem) for p in root.glob("*.jpg"))


def load_human_seg(sample_id):
    """Photo (BGR) and person mask (bool) at the photo's size."""
    root = SHARED / "data" / "human_seg"
    image = cv2.imread(str(root / "images" / f"{sample_id}.jpg"), cv2.IMREAD_COLOR)
    mask = cv2.imread(str(root / "masks" / f"{sample_id}.png"), cv2.IMREAD_GRAYSCALE)
    if image is None or mask is None:
        raise FileNotFoundError(f"human_seg sample {sample_id} is missing")
    if mask.shape != image.shape[:2]:
        # 157 masks are stored smaller than their photo (same aspect ratio).
        mask = cv2.resize(mask, (image.shape[1], image.shape[0]),
                          interpolation=cv2.INTER_NEAREST)
    return image, mask > 127


def make_split(seed=5, val_fraction=0.2):
    """Fixed train/validation split of human_seg by seeded shuffle; written once."""
    if SPLIT_FILE.exists():
        return json.loads(SPLIT_FILE.read_text())
    ids = human_seg_ids()
    rng = random.Random(seed)
    rng.shuffle(ids)
    n_val = int(round(len(ids) * val_fraction))
    split = {"seed": seed, "val_fraction": val_fraction,
             "train": sorted(ids[n_val:]), "val": sorted(ids[:n_val])}
    SPLIT_FILE.parent.mkdir(parents=True, exist_ok=True)
    SPLIT_FILE.write_text(json.dumps(split, indent=1) + "\n")
    return split


def load_split():
    return json.loads(SPLIT_FILE.read_text())


def bonn_frames(step=4):
    root = SHARED / "data" / "bonn_crowd_dev"
    names = []
    for line in (root / "rgb.txt").read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        names.append(root / line.split()[1])
    return names[::step]


SYNTH_PERSON_LABEL = 15  # `pspslam synth` mask/*.png: 0 static, 15 person, 100 carried box


def synth_frames(sequence, step):
    """Every step-th frame of a `pspslam synth` sequence: (colour path, mask path) pairs."""
    sequence = Path(sequence)

    def listed(name):
        lines = (sequence / name).read_text().splitlines()
        return [sequence / line.split()[1] for line in lines
                if line.strip() and not line.startswith("#")]

    colour, masks = listed("rgb.txt"), listed("mask.txt")
    if len(colour) != len(masks):
        raise ValueError(f"{sequence}: {len(colour)} colour frames but {len(masks)} masks")
    return list(zip(colour, masks))[::step]


def load_synth_frame(colour, mask):
    """Rendered frame (BGR) and its person mask (bool); a carried box is not a person."""
    image = cv2.imread(str(colour), cv2.IMREAD_COLOR)
    labels = cv2.imread(str(mask), cv2.IMREAD_UNCHANGED)
    if image is None or labels is None:
        raise FileNotFoundError(f"synthetic frame {colour} or its mask {mask} is missing")
    return image, labels == SYNTH_PERSON_LABEL


def person_iou(labels, mask):
    pred = labels == PERSON
    union = np.logical_or(pred, mask).sum()
    if union == 0:
        return 1.0
    return float(np.logical_and(pred, mask).sum() / union)
