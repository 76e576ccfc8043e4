#!/usr/bin/env python3
"""Do a sequence's depth stamps say when its depth images were captured? Measured from the images.

usage: tools/calibration/depth_sync_check.py SEQUENCE [--depth-factor 5000] [--every 1]
       [--max-shift 5] [--csv FILE]

A TUM-layout RGB-D sequence lists a stamp per colour image (rgb.txt) and per depth image
(depth.txt). If the depth image of a pair was really captured delta = t_depth - t_colour away
from its colour image, then while the image moves sideways at flow_x px/s its depth edges lie
flow_x * delta px from where the colour image has them, a different shift in every frame. Per
frame this script measures where the colour edges lie horizontally relative to the depth edges
(the score profile of depth_registration_shift.py, in one dimension, sub-pixel by a parabola
through the best step), and predicts that shift as -flow_x * delta, flow_x the median horizontal
optical flow (Farneback) between the frame's two neighbours. It prints the regression of the
measured shift on the predicted one over all frames:
  slope ~1 and a clear correlation: the stamps are capture instants, the offset is real;
  slope ~0: the stamps do not describe when the images were taken (e.g. host arrival times).
The vertical offset is found first over every 10th pair (the registration shift, which
`camera.depth_registration_shift_px` removes; 1 px on bonn_crowd_dev) and held. Uses colour and
depth only, never the ground truth. Needs Debian's python3-opencv and python3-numpy.

Checked on synthetic Kinect sequences whose depth stamps are the true capture instants (`pspslam
synth --sensor kinect`, rolling shutter and sync-offset the only faults): hand-held, slope 0.83,
correlation 0.77. Fast motion defeats it: on the 67 deg/s loop the predicted shifts reach the
search window and the image motion is far from one flow (correlation 0.20).
"""
import argparse
import os
import sys
from pathlib import Path

import cv2
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from depth_registration_shift import depth_edges, gradient, read_list, score  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("sequence")
    parser.add_argument("--depth-factor", type=float, default=5000.0)
    parser.add_argument("--every", type=int, default=1)
    parser.add_argument("--max-shift", type=float, default=5.0)
    parser.add_argument("--csv", help="write frame, delta_s, flow_px_per_s, predicted, measured")
    args = parser.parse_args()
    colour = read_list(os.path.join(args.sequence, "rgb.txt"))
    depth = read_list(os.path.join(args.sequence, "depth.txt"))
    depth_stamps = np.array([t for t, _ in depth])

    def pair(k):
        t = colour[k][0]
        j = int(np.argmin(np.abs(depth_stamps - t)))
        if abs(depth_stamps[j] - t) > 0.02:
            return None
        d = cv2.imread(os.path.join(args.sequence, depth[j][1]), cv2.IMREAD_UNCHANGED)
        if d is None:
            return None
        return depth_stamps[j] - t, d.astype(np.float32) / args.depth_factor

    def gray(k):
        image = cv2.imread(os.path.join(args.sequence, colour[k][1]), cv2.IMREAD_GRAYSCALE)
        if image is None:
            raise SystemExit(f"error: cannot read {colour[k][1]} listed in rgb.txt")
        return image

    # The vertical offset, held below: a 2-D search over every 10th pair.
    steps = np.arange(-3, 3.001, 0.5)
    total = np.zeros((len(steps), len(steps)))
    for k in range(0, len(colour), 10):
        found = pair(k)
        if found is None:
            continue
        edges = depth_edges(found[1])
        if edges.sum() == 0:
            continue
        grad = gradient(gray(k))
        for a, dy in enumerate(steps):
            for b, dx in enumerate(steps):
                total[a, b] += score(edges, grad, dx, dy)
    dy = steps[np.unravel_index(total.argmax(), total.shape)[0]]

    step = 0.25
    shifts = np.arange(-args.max_shift, args.max_shift + 1e-9, step)
    rows = []
    for k in range(1, len(colour) - 1, args.every):
        found = pair(k)
        if found is None:
            continue
        delta, d = found
        edges = depth_edges(d, vertical_only=True)
        if edges.sum() < 200:
            continue
        grad = gradient(gray(k))
        profile = np.array([score(edges, grad, dx, dy) for dx in shifts])
        i = int(profile.argmax())
        if not 0 < i < len(profile) - 1:
            continue  # the best shift is at the edge of the search: no peak to refine
        a, b, c = profile[i - 1: i + 2]
        curvature = a - 2 * b + c
        measured = shifts[i] + (0.5 * (a - c) / curvature * step if curvature != 0 else 0.0)
        flow = cv2.calcOpticalFlowFarneback(gray(k - 1), gray(k + 1), None, 0.5, 3, 21, 3, 5,
                                            1.1, 0)
        flow_x = float(np.median(flow[..., 0])) / (colour[k + 1][0] - colour[k - 1][0])
        rows.append((k, delta, flow_x, -flow_x * delta, measured))
    if len(rows) < 10:
        raise SystemExit(f"error: only {len(rows)} frames of {args.sequence} have depth edges "
                         "and a sharp colour/depth alignment")
    table = np.array(rows)
    if args.csv:
        np.savetxt(args.csv, table, fmt="%.6f", delimiter=",",
                   header="frame,delta_s,flow_px_per_s,predicted_px,measured_px", comments="")
    predicted, measured = table[:, 3], table[:, 4]
    deltas = table[:, 1]
    print(f"{len(table)} frames; depth stamp - colour stamp: median {np.median(deltas) * 1e3:+.1f}"
          f" ms, range {deltas.min() * 1e3:+.1f} .. {deltas.max() * 1e3:+.1f} ms; vertical offset "
          f"held at {dy:+.1f} px")
    if np.std(predicted) < 1e-6:
        print("the stamps predict no shift in any frame (equal stamps or no motion): "
              "nothing to test")
        return
    slope, intercept = np.polyfit(predicted, measured, 1)
    correlation = np.corrcoef(predicted, measured)[0, 1]
    print(f"measured shift = {slope:.2f} x predicted {intercept:+.2f} px; correlation "
          f"{correlation:.2f}; spread of the predicted {np.std(predicted):.2f} px, of the "
          f"measured {np.std(measured):.2f} px")
    # Control: the same flows with the stamp differences of other frames (1000 shuffles).
    rng = np.random.default_rng(0)
    shuffled = np.array([np.corrcoef(-table[:, 2] * rng.permutation(deltas), measured)[0, 1]
                         for _ in range(1000)])
    print(f"control, stamp differences shuffled across frames: correlation 99th percentile "
          f"{np.percentile(shuffled, 99):.2f}, largest {shuffled.max():.2f} of 1000")
    if correlation > max(0.3, shuffled.max()) and slope > 0.5:
        print("the depth stamps are capture instants: depth and colour are taken apart in time")
    else:
        print("the depth stamps do not predict where the depth edges lie")


if __name__ == "__main__":
    main()
