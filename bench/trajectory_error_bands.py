#!/usr/bin/env python3
"""Splits a trajectory's ATE into what a smoother would remove and what it would not.

usage: bench/trajectory_error_bands.py GROUNDTRUTH ESTIMATE [--window 9] [--stamps FILE]
                                      [--stretch N] [--gt-body-to-camera FILE]

After the SE(3) alignment of `pspslam eval` (nearest ground-truth pose within 20 ms, positions
only), the per-frame error e_i is split into its moving average over --window frames
(low-frequency: drift and wander) and the rest (high-frequency: frame-to-frame jitter). Also
prints the ground truth's own jitter (the same split of its positions), how far nearest-stamp
association moves the ground truth from its interpolation at the estimate's stamps, and how much a
marker-to-camera lever arm would explain: the ATE after also fitting a fixed offset l in the
camera frame (gt_i ~ R (p_i + R_i l) + t). Used in docs/benchmarks.md to say where bonn_crowd_dev's
error comes from; it is a diagnosis, not a metric (the lever arm is fitted to the ground truth).
--stamps FILE keeps only the estimate's poses at FILE's timestamps (e.g. a run's keyframes.txt, to
compare the tracked poses of the keyframe frames with the final keyframe poses); --stretch N also
prints the ATE RMSE of every N consecutive poses (N = 1: every pose), from the one alignment.
--gt-body-to-camera FILE (one line 'tx ty tz qx qy qz qw', as `pspslam eval` takes it, e.g. the
body_to_camera.txt of `pspslam synth --sensor kinect`) first moves the ground truth from its
marker body onto the camera.
Needs Debian's python3-numpy (`scripts/install-deps --train` installs it).
"""
import argparse

import numpy as np


def load(path):
    rows = [line.split()[:8] for line in open(path) if line.strip() and not line.startswith("#")]
    return np.array(rows, dtype=float)


def rotation(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def align(model, data):
    """R, t minimising |R model + t - data| (Horn/Umeyama without scale)."""
    mm, dm = model.mean(0), data.mean(0)
    u, _, vt = np.linalg.svd((data - dm).T @ (model - mm))
    fix = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    r = u @ fix @ vt
    return r, dm - r @ mm


def rms(vectors):
    return 1e3 * np.sqrt((np.linalg.norm(vectors, axis=1) ** 2).mean())


def moving_average(values, window):
    kernel = np.ones(window) / window
    return np.stack([np.convolve(values[:, k], kernel, "same") for k in range(3)], 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("groundtruth")
    parser.add_argument("estimate")
    parser.add_argument("--window", type=int, default=9)
    parser.add_argument("--stamps", help="evaluate only at the timestamps of this trajectory file")
    parser.add_argument("--stretch", type=int, default=0, help="also print the RMSE per N poses")
    parser.add_argument("--gt-body-to-camera", help="T_body_camera: tx ty tz qx qy qz qw")
    args = parser.parse_args()
    gt, est = load(args.groundtruth), load(args.estimate)
    if args.gt_body_to_camera:
        # Positions only are compared, so only the camera centre moves: p + R_world_body t.
        body = load(args.gt_body_to_camera)[0]
        gt[:, 1:4] += np.array([rotation(q) @ body[0:3] for q in gt[:, 4:8]])
    if args.stamps:
        stamps = load(args.stamps)[:, 0]
        est = est[[np.min(np.abs(stamps - t)) < 1e-4 for t in est[:, 0]]]
    nearest = np.array([np.argmin(np.abs(gt[:, 0] - t)) for t in est[:, 0]])
    keep = np.abs(gt[nearest, 0] - est[:, 0]) < 0.02
    # What nearest-stamp association costs: the matched ground-truth positions against the ground
    # truth interpolated at the estimate's own stamps.
    interpolated = np.stack([np.interp(est[keep, 0], gt[:, 0], gt[:, k]) for k in (1, 2, 3)], 1)
    association_shift = rms(gt[nearest[keep], 1:4] - interpolated)
    est, gt = est[keep], gt[nearest[keep]]
    p, g = est[:, 1:4], gt[:, 1:4]
    r, t = align(p, g)
    error = p @ r.T + t - g
    w = args.window
    inner = slice(w, len(error) - w)  # the average is biased where the window leaves the ends
    low = moving_average(error, w)
    print(f"poses {len(error)}, ATE RMSE {rms(error):.1f} mm")
    for first in range(0, len(error), args.stretch or len(error)):
        if not args.stretch:
            break
        last = min(first + args.stretch, len(error)) - 1
        print(f"  poses {first}-{last} (t = {est[first, 0] - est[0, 0]:.2f}-"
              f"{est[last, 0] - est[0, 0]:.2f} s): {rms(error[first:last + 1]):.1f} mm")
    print(f"low-frequency ({w}-frame average) {rms(low[inner]):.1f} mm, "
          f"high-frequency {rms((error - low)[inner]):.1f} mm")
    print(f"ground truth's own high-frequency part {rms((g - moving_average(g, w))[inner]):.1f} mm; "
          f"nearest-stamp association moves it by {association_shift:.1f} mm RMS")
    rotations = [rotation(q) for q in est[:, 4:8]]
    lever = np.zeros(3)
    for _ in range(20):  # alternate: alignment for a fixed lever arm, lever arm for a fixed alignment
        shifted = p + np.array([rc @ lever for rc in rotations])
        r, t = align(shifted, g)
        system = np.vstack([r @ rc for rc in rotations])
        lever = np.linalg.lstsq(system, (g - t - p @ r.T).reshape(-1), rcond=None)[0]
    shifted = p + np.array([rc @ lever for rc in rotations])
    r, t = align(shifted, g)
    print(f"with a fitted lever arm ({', '.join(f'{1e3 * v:.0f}' for v in lever)} mm in the camera "
          f"frame): ATE {rms(shifted @ r.T + t - g):.1f} mm")


if __name__ == "__main__":
    main()
