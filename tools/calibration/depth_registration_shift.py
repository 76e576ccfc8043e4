#!/usr/bin/env python3
"""Estimates how far a sensor-registered depth image sits from its colour image.

usage: tools/calibration/depth_registration_shift.py SEQUENCE [--depth-factor 5000] [--every 10]
       [--max-shift 3] [--step 0.25]

For every --every-th associated colour/depth pair of a TUM-layout sequence, depth edges (a
relative depth jump > 15 % across a Sobel kernel, away from holes) are scored against the colour
image's gradient magnitude shifted by (dx, dy) on a sub-pixel grid; the shift with the highest
total score is where colour edges lie relative to depth edges. Prints the score profile and the
whole-pixel value for the config key `camera.depth_registration_shift_px: [dx, dy]` (depth of
colour pixel (u, v) read at (u + dx, v + dy)). Uses colour and depth only, never the ground truth.
Needs Debian's python3-opencv and python3-numpy.
"""
import argparse
import os

import cv2
import numpy as np


def read_list(path):
    rows = [line.split() for line in open(path) if line.strip() and not line.startswith("#")]
    return [(float(r[0]), r[1]) for r in rows]


# The edge alignment below is shared with depth_sync_check.py, which imports it.
def depth_edges(depth, vertical_only=False):
    """Depth edges (a relative jump > 15 % across a Sobel kernel, away from holes) as 0/1 floats;
    vertical_only keeps those across which depth changes left to right."""
    valid = cv2.erode((depth > 0).astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
    gx = np.abs(cv2.Sobel(depth, cv2.CV_32F, 1, 0))
    jump = np.hypot(gx, cv2.Sobel(depth, cv2.CV_32F, 0, 1))
    edges = (jump / (depth + 1e-3) > 0.15) & valid
    if vertical_only:
        edges &= gx > 0.7 * jump
    return edges.astype(np.float32)


def gradient(gray):
    """The colour image's gradient magnitude, normalised to a mean of 1."""
    g = gray.astype(np.float32)
    magnitude = np.hypot(cv2.Sobel(g, cv2.CV_32F, 1, 0), cv2.Sobel(g, cv2.CV_32F, 0, 1))
    return magnitude / (magnitude.mean() + 1e-6)


def score(edges, grad, dx, dy):
    """Mean colour gradient on the depth edges with the colour image shifted by (dx, dy):
    shifted(u, v) = grad(u + dx, v + dy), the colour edge dx, dy away from the depth edge."""
    height, width = grad.shape
    warp = np.float32([[1, 0, dx], [0, 1, dy]])
    shifted = cv2.warpAffine(grad, warp, (width, height),
                             flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP)
    inner = (slice(10, -10), slice(10, -10))
    return (edges[inner] * shifted[inner]).sum() / edges.sum()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("sequence")
    parser.add_argument("--depth-factor", type=float, default=5000.0)
    parser.add_argument("--every", type=int, default=10)
    parser.add_argument("--max-shift", type=float, default=3.0)
    parser.add_argument("--step", type=float, default=0.25)
    args = parser.parse_args()
    colour = read_list(os.path.join(args.sequence, "rgb.txt"))
    depth = read_list(os.path.join(args.sequence, "depth.txt"))
    depth_stamps = np.array([t for t, _ in depth])
    shifts = np.arange(-args.max_shift, args.max_shift + 1e-9, args.step)
    total = np.zeros((len(shifts), len(shifts)))  # [dy, dx]
    used = 0
    for t, colour_file in colour[:: args.every]:
        j = int(np.argmin(np.abs(depth_stamps - t)))
        depth_path = os.path.join(args.sequence, depth[j][1])
        if abs(depth_stamps[j] - t) > 0.02 or not os.path.exists(depth_path):
            continue
        d = cv2.imread(depth_path, cv2.IMREAD_UNCHANGED).astype(np.float32) / args.depth_factor
        edges = depth_edges(d)
        if edges.sum() == 0:
            continue
        grad = gradient(cv2.imread(os.path.join(args.sequence, colour_file), cv2.IMREAD_GRAYSCALE))
        for a, dy in enumerate(shifts):
            for b, dx in enumerate(shifts):
                total[a, b] += score(edges, grad, dx, dy)
        used += 1
    if used == 0:
        raise SystemExit("error: no colour/depth pair with depth edges in " + args.sequence)
    a, b = np.unravel_index(total.argmax(), total.shape)
    dy, dx = shifts[a], shifts[b]
    print(f"{used} frame pairs; colour edges lie at dx {dx:+.2f}, dy {dy:+.2f} px from depth edges")
    print("score over dy at that dx:", " ".join(f"{s:.3f}" for s in total[:, b] / total.max()))
    print("score over dx at that dy:", " ".join(f"{s:.3f}" for s in total[a, :] / total.max()))
    print(f"camera.depth_registration_shift_px: [{int(round(-dx))}, {int(round(-dy))}]")


if __name__ == "__main__":
    main()
