#!/usr/bin/env python3
"""Where the final trajectory's error of a loop run sits: at the keyframes, which loop closing and
the global BA move, or on the frames between them, which only follow their keyframes.

usage: bench/loop_error_split.py GROUNDTRUTH RUN [--floor OFF_RUN] [--json]

RUN is a `pspslam run --out` folder (trajectory.txt, trajectory_refined.txt, keyframes.txt).
Prints, in mm (positions, SE(3) alignment as `pspslam eval`, nearest ground truth within 20 ms):
  online         ATE of trajectory.txt
  final          ATE of trajectory_refined.txt
  keyframes      ATE of keyframes.txt (the final keyframe poses, aligned on their own)
  final @kf      the final trajectory's error at the keyframe frames / at all other frames, from
  final @others  the one alignment of the whole final trajectory
--floor OFF_RUN (a run of the same sequence without loop closing, hence one map epoch) adds
  floor          the final-trajectory method's floor on that run: every keyframe put exactly on
                 the ground truth (its correction D = T_gt * T_tracked^-1, after the alignment of
                 the online trajectory), every other frame moved by D interpolated in time
                 between its keyframes (rotation slerp, translation linear), as
                 src/pspslam/tracking/trajectory_refinement.cpp does. What is left is the frames'
                 own tracking error relative to their keyframes, which no keyframe correction
                 removes.
  floor_centred  the same with each correction turning about its keyframe's camera centre (an
                 interpolation that does not depend on the world origin): equal to 0.1 mm on the
                 four loops of docs/benchmarks.md (2026-12-01)
--json prints the figures as one JSON object instead.
Needs Debian's python3-numpy (run it with /usr/bin/python3).
"""
import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from trajectory_error_bands import align, load, rotation  # noqa: E402


def nearest(gt, stamps):
    index = np.array([np.argmin(np.abs(gt[:, 0] - t)) for t in stamps])
    keep = np.abs(gt[index, 0] - stamps) < 0.02
    return index, keep


def position_errors(gt, est):
    """Per-pose position error (m) after the SE(3) alignment of est onto gt, and the alignment."""
    index, keep = nearest(gt, est[:, 0])
    est, index = est[keep], index[keep]
    r, t = align(est[:, 1:4], gt[index, 1:4])
    return est[:, 0], np.linalg.norm(est[:, 1:4] @ r.T + t - gt[index, 1:4], axis=1), (r, t)


def rmse_mm(errors):
    return float(1e3 * np.sqrt((errors ** 2).mean())) if len(errors) else float("nan")


def homogeneous(row):
    m = np.eye(4)
    m[:3, :3] = rotation(row[4:8])
    m[:3, 3] = row[1:4]
    return m


def quaternion(m):
    """Unit quaternion (x, y, z, w) of a rotation matrix."""
    w = np.sqrt(max(0.0, 1.0 + np.trace(m))) / 2.0
    x = np.copysign(np.sqrt(max(0.0, 1.0 + m[0, 0] - m[1, 1] - m[2, 2])) / 2.0, m[2, 1] - m[1, 2])
    y = np.copysign(np.sqrt(max(0.0, 1.0 - m[0, 0] + m[1, 1] - m[2, 2])) / 2.0, m[0, 2] - m[2, 0])
    z = np.copysign(np.sqrt(max(0.0, 1.0 - m[0, 0] - m[1, 1] + m[2, 2])) / 2.0, m[1, 0] - m[0, 1])
    q = np.array([x, y, z, w])
    return q / np.linalg.norm(q)


def slerp(q0, q1, s):
    dot = q0 @ q1
    if dot < 0.0:
        q1, dot = -q1, -dot
    if dot > 0.9995:
        q = q0 + s * (q1 - q0)
        return q / np.linalg.norm(q)
    theta = np.arccos(dot)
    return (np.sin((1.0 - s) * theta) * q0 + np.sin(s * theta) * q1) / np.sin(theta)


def floor_mm(gt, run, centred=False):
    """RMSE (mm) of the final-trajectory method with keyframes exactly on the ground truth;
    centred: each correction turns about its keyframe's camera centre, not the world origin."""
    tracked = load(run / "trajectory.txt")
    keyframe_stamps = load(run / "keyframes.txt")[:, 0]
    index, keep = nearest(gt, tracked[:, 0])
    tracked, index = tracked[keep], index[keep]
    r, t = align(tracked[:, 1:4], gt[index, 1:4])
    alignment = np.eye(4)
    alignment[:3, :3], alignment[:3, 3] = r, t
    poses = [alignment @ homogeneous(row) for row in tracked]
    truth = [homogeneous(gt[i]) for i in index]
    keyframes = np.array([k for k in range(len(tracked))
                          if np.min(np.abs(keyframe_stamps - tracked[k, 0])) < 1e-4])
    correction = {k: truth[k] @ np.linalg.inv(poses[k]) for k in keyframes}
    errors = []
    for f, pose in enumerate(poses):
        after = np.searchsorted(keyframes, f)
        if after == 0 or after == len(keyframes):
            d = correction[keyframes[0 if after == 0 else -1]]
        else:
            a, b = keyframes[after - 1], keyframes[after]
            s = (tracked[f, 0] - tracked[a, 0]) / (tracked[b, 0] - tracked[a, 0])
            d = np.eye(4)
            d[:3, :3] = rotation(slerp(quaternion(correction[a][:3, :3]),
                                       quaternion(correction[b][:3, :3]), s))
            d[:3, 3] = (1.0 - s) * correction[a][:3, 3] + s * correction[b][:3, 3]
            if centred:
                pivot = (1.0 - s) * poses[a][:3, 3] + s * poses[b][:3, 3]
                moved = (1.0 - s) * truth[a][:3, 3] + s * truth[b][:3, 3]
                d[:3, 3] = moved - d[:3, :3] @ pivot
        errors.append(np.linalg.norm((d @ pose)[:3, 3] - truth[f][:3, 3]))
    return rmse_mm(np.array(errors)), len(keyframes)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("groundtruth")
    parser.add_argument("run", type=Path)
    parser.add_argument("--floor", type=Path, help="a run of the same sequence without loops")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    gt = load(args.groundtruth)
    figures = {}
    _, online, _ = position_errors(gt, load(args.run / "trajectory.txt"))
    stamps, final, _ = position_errors(gt, load(args.run / "trajectory_refined.txt"))
    keyframes = load(args.run / "keyframes.txt")
    _, keyframe_errors, _ = position_errors(gt, keyframes)
    at_keyframe = np.array([np.min(np.abs(keyframes[:, 0] - s)) < 1e-4 for s in stamps])
    figures["online"] = rmse_mm(online)
    figures["final"] = rmse_mm(final)
    figures["keyframes"] = rmse_mm(keyframe_errors)
    figures["keyframe_count"] = int(len(keyframes))
    figures["final_at_keyframes"] = rmse_mm(final[at_keyframe])
    figures["final_at_others"] = rmse_mm(final[~at_keyframe])
    if args.floor:
        figures["floor"], figures["floor_keyframes"] = floor_mm(gt, args.floor)
        figures["floor_centred"], _ = floor_mm(gt, args.floor, centred=True)
    if args.json:
        print(json.dumps(figures))
        return
    print(f"online {figures['online']:.1f} mm, final {figures['final']:.1f} mm, "
          f"keyframes {figures['keyframes']:.1f} mm ({figures['keyframe_count']})")
    print(f"final @kf {figures['final_at_keyframes']:.1f} mm, "
          f"final @others {figures['final_at_others']:.1f} mm")
    if args.floor:
        print(f"floor (keyframes exact, {figures['floor_keyframes']} keyframes of {args.floor}): "
              f"{figures['floor']:.1f} mm; turning about the keyframes' centres "
              f"{figures['floor_centred']:.1f} mm")


if __name__ == "__main__":
    main()
