#!/usr/bin/env python3
"""ATE RMSE of two runs of one sequence over the frames both tracked, each aligned on those frames
alone: a fair comparison when one run lost frames the other kept (the lost frames are often the
hard ones).

usage: bench/common_frames_ate.py GROUNDTRUTH A B [--sim3]

A and B are TUM trajectories (e.g. two runs' trajectory.txt). Prints the common frame count and
the ATE RMSE of A and of B in mm (positions, nearest ground truth within 20 ms; SE(3) alignment,
or Sim(3) with --sim3 for monocular runs, as `pspslam eval` aligns).
Needs Debian's python3-numpy (run it with /usr/bin/python3).
"""
import argparse

import numpy as np

from tum_numpy import load_positions, umeyama


def ate_mm(P, Q, with_scale):
    s, R, t = umeyama(P, Q, with_scale)
    errors = np.linalg.norm((s * (R @ P.T)).T + t - Q, axis=1)
    return np.sqrt((errors ** 2).mean()) * 1000


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("groundtruth")
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--sim3", action="store_true")
    args = parser.parse_args()
    ground_truth = load_positions(args.groundtruth, 4)
    stamps = np.array(sorted(ground_truth))
    a, b = load_positions(args.a, 4), load_positions(args.b, 4)

    def truth(stamp):
        i = int(np.argmin(np.abs(stamps - stamp)))
        return ground_truth[stamps[i]] if abs(stamps[i] - stamp) < 0.02 else None

    common = [t for t in sorted(set(a) & set(b)) if truth(t) is not None]
    if len(common) < 3:
        raise SystemExit(f"common_frames_ate: only {len(common)} frames in common with the ground truth")
    Q = np.array([truth(t) for t in common])
    ate_a = ate_mm(np.array([a[t] for t in common]), Q, args.sim3)
    ate_b = ate_mm(np.array([b[t] for t in common]), Q, args.sim3)
    print(f"common {len(common)} frames (A {len(a)}, B {len(b)}): A {ate_a:.1f} mm, B {ate_b:.1f} mm")


if __name__ == "__main__":
    main()
