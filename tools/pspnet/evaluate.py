"""Person IoU on the human_seg validation split for segmenter metadata YAMLs, and with
--synth on `pspslam synth` sequences against their rendered person masks (pooled over every
--synth-step-th frame of each sequence).

Uses cv2.dnn with the same preprocessing as the C++ OnnxSegmenter (stretch to the
network input, bilinear; (p - mean) / std; arg-max; nearest-neighbour resize back),
as a cross-check of bench_segmentation's IoU table.
"""

import argparse
import time
from pathlib import Path

import cv2
import numpy as np
import yaml

import common


def load_net(meta_file):
    meta = yaml.safe_load(Path(meta_file).read_text())
    ref = meta["onnx"]
    if ref.startswith("${shared}/"):
        path = common.SHARED / ref[len("${shared}/"):]
    else:
        path = Path(meta_file).parent / ref
    if meta["input"]["channel_order"] != "RGB":
        raise ValueError("only RGB models are handled here")
    return meta, cv2.dnn.readNetFromONNX(str(path))


def network_labels(net, meta, bgr):
    """Arg-max labels at the network's input size (the C++ path's preprocessing)."""
    net.setInput(common.to_blob(bgr, meta["input"]["width"], meta["input"]["height"],
                                meta["input"]["mean"], meta["input"]["std"]))
    return net.forward()[0].argmax(0).astype(np.uint8)


def at_size_of(labels, image):
    """Labels resized (nearest neighbour) to the size of `image`."""
    return cv2.resize(labels, (image.shape[1], image.shape[0]), interpolation=cv2.INTER_NEAREST)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("models", nargs="+", help="metadata YAML files")
    parser.add_argument("--threads", type=int, default=2, help="OpenCV threads")
    parser.add_argument("--synth", nargs="*", default=[], help="`pspslam synth` sequence folders")
    parser.add_argument("--synth-step", type=int, default=12)
    args = parser.parse_args()
    cv2.setNumThreads(args.threads)
    ids = common.load_split()["val"]
    for meta_file in args.models:
        meta, net = load_net(meta_file)
        w, h = meta["input"]["width"], meta["input"]["height"]
        ious, times = [], []
        for sample_id in ids:
            bgr, gt = common.load_human_seg(sample_id)
            t0 = time.perf_counter()
            labels = network_labels(net, meta, bgr)
            times.append(time.perf_counter() - t0)
            ious.append(common.person_iou(at_size_of(labels, gt), gt))
        print(f"{meta['name']:34s} {w}x{h}  person IoU {np.mean(ious):.4f} "
              f"({len(ids)} validation photos)  median forward {1000 * np.median(times):.0f} ms")
        for sequence in args.synth:
            frames = common.synth_frames(sequence, args.synth_step)
            inter = union = 0
            for colour, mask in frames:
                bgr, gt = common.load_synth_frame(colour, mask)
                predicted = at_size_of(network_labels(net, meta, bgr), gt) == common.PERSON
                inter += int(np.logical_and(predicted, gt).sum())
                union += int(np.logical_or(predicted, gt).sum())
            print(f"{'':34s} {Path(sequence).name}: person IoU "
                  f"{inter / max(union, 1):.4f} (pooled over {len(frames)} frames)")


if __name__ == "__main__":
    main()
