#!/usr/bin/env python3
"""How a loop correction moved the keyframes: their error before the correction, after it, and in
the run's final map, from the dumps of bench/patches/loop_correction_dumps.patch.

usage: bench/loop_keyframe_states.py GROUNDTRUTH FINAL_KEYFRAMES STATE... [--sim3] [--from F --to T]

FINAL_KEYFRAMES is the run's keyframes.txt; each STATE a TUM file of keyframe poses (the patch
writes kf_before_correction.txt, kf_after_loop_transform.txt and kf_after_correction.txt into
$PSPSLAM_EXP_DUMP_DIR). Prints, in mm, for every file: the ATE RMSE of its keyframes aligned on
their own (SE(3), or Sim(3) with --sim3 for a monocular run), and the range of the errors of the
keyframes of frames F..T (frame = index in the ground truth, nearest within 20 ms) when every file
is put through the one alignment of FINAL_KEYFRAMES to the ground truth — where the final map says
the truth is.
Needs Debian's python3-numpy (run it with /usr/bin/python3).
"""
import argparse

import numpy as np

from tum_numpy import load_positions, umeyama


def associate(ground_truth, estimate):
    stamps = np.array(sorted(ground_truth))
    pairs = []
    for stamp in sorted(estimate):
        i = int(np.argmin(np.abs(stamps - stamp)))
        if abs(stamps[i] - stamp) < 0.02:
            pairs.append((i, estimate[stamp], ground_truth[stamps[i]]))
    return pairs


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("groundtruth")
    parser.add_argument("final_keyframes")
    parser.add_argument("states", nargs="+")
    parser.add_argument("--sim3", action="store_true")
    parser.add_argument("--from", dest="first", type=int, default=0)
    parser.add_argument("--to", dest="last", type=int, default=10**9)
    args = parser.parse_args()
    ground_truth = load_positions(args.groundtruth)
    final = associate(ground_truth, load_positions(args.final_keyframes))
    s, R, t = umeyama(np.array([p for _, p, _ in final]), np.array([q for _, _, q in final]),
                        args.sim3)
    for path in [args.final_keyframes] + args.states:
        pairs = associate(ground_truth, load_positions(path))
        P = np.array([p for _, p, _ in pairs])
        Q = np.array([q for _, _, q in pairs])
        s_own, R_own, t_own = umeyama(P, Q, args.sim3)
        own = np.linalg.norm((s_own * (R_own @ P.T)).T + t_own - Q, axis=1) * 1000
        in_final = np.linalg.norm((s * (R @ P.T)).T + t - Q, axis=1) * 1000
        window = [e for (frame, _, _), e in zip(pairs, in_final) if args.first <= frame <= args.last]
        span = f"{min(window):.1f}-{max(window):.1f}" if window else "-"
        print(f"{path}: {len(pairs)} keyframes, aligned on their own {np.sqrt((own ** 2).mean()):.1f} mm; "
              f"frames {args.first}-{args.last} in the final alignment {span} mm")


if __name__ == "__main__":
    main()
