#!/usr/bin/env python3
"""Where the keyframes after BA lose to the online poses: the map's first keyframes or the rest.

usage: /usr/bin/python3 bench/keyframe_error_split.py PANEL_WORK [--run base|variant] [--first N]
       [--cell NAME]

PANEL_WORK is a `bench/accuracy_panel.py --work` folder. For every dev cell, the keyframes after
BA (run/keyframes.txt) and the online poses at the same stamps (online_at_keyframes_*.txt) are
each aligned to bonn_crowd_dev's ground truth on all their keyframes (SE(3)); printed: the RMS
error of the first N keyframes and of the rest for both, then the first N of each aligned on their
own and the error of the step lengths between consecutive keyframes, which no alignment touches.
--cell NAME also lists that cell's per-keyframe errors (mm). Ground truth from
$PSPSLAM_SHARED/data/bonn_crowd_dev (default ../shared). Needs numpy (scripts/install-deps --bench).
"""
import argparse
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from tum_numpy import load_positions, umeyama  # noqa: E402


def associated(estimate, truth, stamps):
    """Estimated and true positions of the estimate's stamps within 20 ms of a true one."""
    pairs = []
    for t, p in sorted(estimate.items()):
        i = int(np.argmin(np.abs(stamps - t)))
        if abs(stamps[i] - t) < 0.02:
            pairs.append((p, truth[stamps[i]]))
    return np.array([p for p, _ in pairs]), np.array([q for _, q in pairs])


def aligned_errors(P, Q):
    _, R, t = umeyama(P, Q, False)
    return np.linalg.norm((R @ P.T).T + t - Q, axis=1)


def rms_mm(values):
    return float(np.sqrt(np.mean(values ** 2)) * 1e3)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("work")
    parser.add_argument("--run", default="base", choices=["base", "variant"])
    parser.add_argument("--first", type=int, default=8)
    parser.add_argument("--cell", default="")
    args = parser.parse_args()
    shared = Path(os.environ.get("PSPSLAM_SHARED", "../shared"))
    gt_file = shared / "data/bonn_crowd_dev/groundtruth.txt"
    if not gt_file.is_file():
        sys.exit(f"{gt_file}: not found (set PSPSLAM_SHARED)")
    runs = Path(args.work) / "runs"
    if not runs.is_dir():
        sys.exit(f"{runs}: not a panel folder (bench/accuracy_panel.py --work)")
    truth = load_positions(gt_file)
    stamps = np.array(sorted(truth))
    n = args.first
    print(f"keyframe error (mm), {args.run} runs: first {n} keyframes | the rest; BA vs online")
    for cell in sorted(p.name for p in runs.iterdir() if p.name.startswith("dev")):
        folder = runs / cell / args.run
        online = sorted(folder.glob("online_at_keyframes_*.txt"))
        if not online or not (folder / "run/keyframes.txt").is_file():
            continue
        ba = associated(load_positions(folder / "run/keyframes.txt"), truth, stamps)
        on = associated(load_positions(online[0]), truth, stamps)
        if len(ba[0]) != len(on[0]) or len(ba[0]) <= n:
            print(f"{cell:16s} skipped: {len(ba[0])} vs {len(on[0])} keyframes")
            continue
        e_ba, e_on = aligned_errors(*ba), aligned_errors(*on)
        own = [rms_mm(aligned_errors(P[:n], Q[:n])) for P, Q in (ba, on)]
        steps = [rms_mm(np.abs(np.linalg.norm(np.diff(P[:n], axis=0), axis=1) -
                               np.linalg.norm(np.diff(Q[:n], axis=0), axis=1))) for P, Q in (ba, on)]
        print(f"{cell:16s} n={len(e_ba):3d}  first {rms_mm(e_ba[:n]):5.1f} vs {rms_mm(e_on[:n]):5.1f}"
              f" | rest {rms_mm(e_ba[n:]):5.1f} vs {rms_mm(e_on[n:]):5.1f}"
              f" | first, own alignment {own[0]:5.1f} vs {own[1]:5.1f}"
              f" | step lengths {steps[0]:5.1f} vs {steps[1]:5.1f}")
        if cell == args.cell:
            print("  per keyframe, BA:    ", " ".join(f"{x * 1e3:.0f}" for x in e_ba))
            print("  per keyframe, online:", " ".join(f"{x * 1e3:.0f}" for x in e_on))


if __name__ == "__main__":
    main()
