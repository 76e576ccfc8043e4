#!/usr/bin/env python3
"""ATE RMSE computed independently of pspslam's C++ (a cross-check of `pspslam eval`).

  python3 bench/independent_ate.py GROUNDTRUTH.txt ESTIMATE.txt [--max-dt 0.02]

Both files are TUM trajectories (timestamp tx ty tz qx qy qz qw; '#' comments). Steps, written
from the definitions rather than from our code:
  1. association: every (ground truth, estimate) pair closer than --max-dt seconds is a
     candidate; candidates are taken by increasing time difference, each pose used at most once
     (what TUM's associate.py does);
  2. alignment: the rigid motion (R, t) minimising sum |R est_i + t - gt_i|^2 in closed form
     (Umeyama 1991 without scale: SVD of the cross-covariance of the centred point sets,
     reflection removed through the sign of det);
  3. ATE = root mean square of |R est_i + t - gt_i| over the associated pairs.
Needs numpy only (Debian: python3-numpy). Prints the pair count and the RMSE in metres.
"""
import argparse
import sys

import numpy as np


def read_tum(path):
    stamps, positions = [], []
    with open(path) as stream:
        for number, line in enumerate(stream, 1):
            fields = line.replace(",", " ").split()
            if not fields or fields[0].startswith("#"):
                continue
            if len(fields) != 8:
                sys.exit(f"{path}:{number}: expected 8 fields, got {len(fields)}")
            stamps.append(float(fields[0]))
            positions.append([float(v) for v in fields[1:4]])
    return np.array(stamps), np.array(positions)


def associate(gt_stamps, est_stamps, max_dt):
    candidates = []
    for j, t in enumerate(est_stamps):
        # Only ground-truth stamps within max_dt can pair with t.
        low = np.searchsorted(gt_stamps, t - max_dt, side="left")
        high = np.searchsorted(gt_stamps, t + max_dt, side="right")
        for i in range(low, high):
            dt = abs(gt_stamps[i] - t)
            if dt < max_dt:
                candidates.append((dt, i, j))
    candidates.sort()
    used_gt, used_est, pairs = set(), set(), []
    for _, i, j in candidates:
        if i in used_gt or j in used_est:
            continue
        used_gt.add(i)
        used_est.add(j)
        pairs.append((i, j))
    pairs.sort()
    return pairs


def rigid_alignment(est, gt):
    """R, t minimising |R est + t - gt|^2 (rows are points)."""
    est_mean, gt_mean = est.mean(axis=0), gt.mean(axis=0)
    covariance = (gt - gt_mean).T @ (est - est_mean) / len(est)
    u, _, vt = np.linalg.svd(covariance)
    sign = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        sign[2, 2] = -1.0
    rotation = u @ sign @ vt
    return rotation, gt_mean - rotation @ est_mean


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("groundtruth")
    parser.add_argument("estimate")
    parser.add_argument("--max-dt", type=float, default=0.02)
    args = parser.parse_args()
    gt_stamps, gt_xyz = read_tum(args.groundtruth)
    order = np.argsort(gt_stamps)
    gt_stamps, gt_xyz = gt_stamps[order], gt_xyz[order]
    est_stamps, est_xyz = read_tum(args.estimate)
    pairs = associate(gt_stamps, est_stamps, args.max_dt)
    if len(pairs) < 3:
        sys.exit(f"only {len(pairs)} associated pairs")
    gt = gt_xyz[[i for i, _ in pairs]]
    est = est_xyz[[j for _, j in pairs]]
    rotation, translation = rigid_alignment(est, gt)
    errors = np.linalg.norm(est @ rotation.T + translation - gt, axis=1)
    print(f"pairs {len(pairs)}  ATE RMSE {np.sqrt(np.mean(errors ** 2)):.6f} m  "
          f"mean {errors.mean():.6f} m  max {errors.max():.6f} m")


if __name__ == "__main__":
    main()
