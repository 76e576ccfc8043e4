#!/usr/bin/env python3
"""How well do FAST corners locate a known sub-pixel shift, with and without refinement?

Each colour image (every STEP-th of a sequence's rgb/) is shifted by a random (dx, dy) in
[-1, 1] px with bilinear interpolation; FAST (threshold 20, non-maximum suppression, as the
extractor's first pass at level 0) runs on both; each corner of the original is paired with the
nearest corner of the shifted image within 1.5 px of where it should be, and the error of the
pair's positions against the true shift is reported for three position estimates:
  integer   - FAST's pixel, as `OrbExtractor` returns it
  subpix    - cv.cornerSubPix (window 5x5, 10 iterations), kept only when it moves <= 1 px
  parabola  - a parabola through the Harris response (5x5 central-difference gradients) at the
              corner and its 4-neighbours, peak clamped to +-0.5 px
(the two refinements of bench/patches/subpixel_keypoints.patch). Numpy + OpenCV only.

    /usr/bin/python3 bench/subpixel_shift_check.py ../shared/data/bonn_crowd_dev
"""
import argparse
import glob
import os

import cv2
import numpy as np


def harris(image, x, y):
    patch = image[y - 3:y + 4, x - 3:x + 4].astype(np.float32)
    gx = patch[1:-1, 2:] - patch[1:-1, :-2]
    gy = patch[2:, 1:-1] - patch[:-2, 1:-1]
    xx, yy, xy = (gx * gx).sum(), (gy * gy).sum(), (gx * gy).sum()
    return xx * yy - xy * xy - 0.04 * (xx + yy) ** 2


def parabola_peak(minus, center, plus):
    curvature = minus - 2 * center + plus
    return 0.0 if not curvature < 0 else float(np.clip(0.5 * (minus - plus) / curvature, -0.5, 0.5))


def refine(image, points, method):
    if method == "integer":
        return points.copy()
    out = []
    for x, y in points:
        xi, yi = int(round(x)), int(round(y))
        if method == "parabola":
            c = harris(image, xi, yi)
            out.append((xi + parabola_peak(harris(image, xi - 1, yi), c, harris(image, xi + 1, yi)),
                        yi + parabola_peak(harris(image, xi, yi - 1), c, harris(image, xi, yi + 1))))
        else:
            corner = np.array([[x, y]], np.float32)
            cv2.cornerSubPix(image, corner, (2, 2), (-1, -1),
                             (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 10, 0.01))
            moved = abs(corner[0, 0] - x) <= 1 and abs(corner[0, 1] - y) <= 1
            out.append(tuple(corner[0]) if moved else (x, y))
    return np.array(out)


def inner(points, shape, margin=10):
    keep = ((points[:, 0] > margin) & (points[:, 0] < shape[1] - margin) &
            (points[:, 1] > margin) & (points[:, 1] < shape[0] - margin))
    return points[keep]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("sequence", help="a TUM-layout folder with rgb/")
    parser.add_argument("--step", type=int, default=20, help="every STEP-th image (default 20)")
    parser.add_argument("--images", type=int, default=10, help="how many images (default 10)")
    parser.add_argument("--shifts", type=int, default=3, help="random shifts per image (default 3)")
    args = parser.parse_args()
    files = sorted(glob.glob(os.path.join(args.sequence, "rgb", "*")))[::args.step][:args.images]
    if not files:
        raise SystemExit(f"no images in {os.path.join(args.sequence, 'rgb')}")
    rng = np.random.default_rng(1)
    fast = cv2.FastFeatureDetector_create(20, True)
    errors = {"integer": [], "subpix": [], "parabola": []}
    for path in files:
        gray = cv2.cvtColor(cv2.imread(path), cv2.COLOR_BGR2GRAY)
        for _ in range(args.shifts):
            shift = rng.uniform(-1, 1, 2)
            warp = np.float32([[1, 0, shift[0]], [0, 1, shift[1]]])
            shifted = cv2.warpAffine(gray, warp, (gray.shape[1], gray.shape[0]), flags=cv2.INTER_LINEAR)
            a = inner(np.array([k.pt for k in fast.detect(gray)]), gray.shape)
            b = inner(np.array([k.pt for k in fast.detect(shifted)]), gray.shape)
            expected = a + shift
            distance = np.linalg.norm(expected[:, None, :] - b[None, :, :], axis=2)
            nearest = distance.argmin(1)
            paired = distance[np.arange(len(a)), nearest] < 1.5
            for method, found in errors.items():
                ra, rb = refine(gray, a, method), refine(shifted, b, method)
                found.extend(np.linalg.norm(rb[nearest[paired]] - (ra[paired] + shift), axis=1))
    print(f"{len(files)} images x {args.shifts} shifts of {args.sequence}")
    for method, found in errors.items():
        e = np.array(found)
        print(f"{method:9s} pairs {len(e):6d}  RMS {np.sqrt((e ** 2).mean()):.3f} px  "
              f"median {np.median(e):.3f} px")


if __name__ == "__main__":
    main()
