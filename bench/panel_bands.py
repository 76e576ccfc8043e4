#!/usr/bin/env python3
"""Per cell of a finished accuracy panel: the online (and final) trajectory's ATE split into its
low-frequency part (wander) and high-frequency part (frame-to-frame jitter), baseline and variant.

usage: bench/panel_bands.py WORK [--window 9]

WORK is the --work folder of bench/accuracy_panel.py. The split is bench/trajectory_error_bands.py's
(SE(3) alignment as `pspslam eval`, nearest ground-truth pose within 20 ms; the per-frame error's
moving average over --window frames is the low-frequency part, the rest the high-frequency part,
both as RMS in mm over the frames the window fits), and the online trajectory's lag behind the
ground truth (the time shift that minimises its ATE; compare base with variant, the recording's
clock offset is in both). Cells with a marker-body ground truth are moved
onto the camera by the sequence's body_to_camera.txt. The whole-clip cells only (the person-free and
crowd stretches are not split). Prints a Markdown table and the paired count of cells whose jitter
fell. Needs Debian's python3-numpy.
"""
import argparse
import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import trajectory_error_bands as bands  # noqa: E402


def split(ground_truth, estimate, body, window):
    gt, est = bands.load(ground_truth), bands.load(estimate)
    if body is not None:
        offset = bands.load(body)[0]
        gt[:, 1:4] += np.array([bands.rotation(q) @ offset[0:3] for q in gt[:, 4:8]])
    nearest = np.array([np.argmin(np.abs(gt[:, 0] - t)) for t in est[:, 0]])
    keep = np.abs(gt[nearest, 0] - est[:, 0]) < 0.02
    p, g = est[keep, 1:4], gt[nearest[keep], 1:4]
    r, t = bands.align(p, g)
    error = p @ r.T + t - g
    low = bands.moving_average(error, window)
    inner = slice(window, len(error) - window)
    return bands.rms(error), bands.rms(low[inner]), bands.rms((error - low)[inner])


def lag_ms(ground_truth, estimate, body, search_ms=150):
    """How far the estimate runs behind the ground truth: the shift d (ms, 1 ms steps within
    +-search_ms) that minimises the ATE of est(t) against the ground truth interpolated at t - d.
    The recording's own clock offset between the cameras and motion capture is in it too, so only
    the difference between two runs of the same cell says whether a change added lag."""
    gt, est = bands.load(ground_truth), bands.load(estimate)
    if body is not None:
        offset = bands.load(body)[0]
        gt[:, 1:4] += np.array([bands.rotation(q) @ offset[0:3] for q in gt[:, 4:8]])
    inside = (est[:, 0] > gt[0, 0] + search_ms / 1e3) & (est[:, 0] < gt[-1, 0] - search_ms / 1e3)
    stamps, p = est[inside, 0], est[inside, 1:4]
    best = None
    for d in range(-search_ms, search_ms + 1):
        g = np.stack([np.interp(stamps - d / 1e3, gt[:, 0], gt[:, k]) for k in (1, 2, 3)], 1)
        r, t = bands.align(p, g)
        ate = bands.rms(p @ r.T + t - g)
        if best is None or ate < best[0]:
            best = (ate, d)
    return best[1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("work")
    parser.add_argument("--window", type=int, default=9)
    args = parser.parse_args()
    runs = Path(args.work) / "runs"
    print("| cell | base online ATE (low / high) | var online ATE (low / high) | "
          "base final (low / high) | var final (low / high) | Δ online high | "
          "online lag base / var (ms) |")
    print("|---|---|---|---|---|---|---|")
    deltas, fell = [], 0
    for cell in sorted(p.name for p in runs.iterdir()):
        row = {}
        for label in ("base", "variant"):
            out = runs / cell / label
            command = (out / "log.txt").read_text().split("\n")[0].split()
            sequence = Path(command[command.index("--sequence") + 1])
            body = sequence / "body_to_camera.txt"
            body = body if body.exists() else None
            for name in ("trajectory.txt", "trajectory_refined.txt"):
                row[label, name] = split(sequence / "groundtruth.txt", out / "run" / name, body,
                                         args.window)
            row[label, "lag"] = lag_ms(sequence / "groundtruth.txt", out / "run" / "trajectory.txt",
                                       body)
        delta = row["variant", "trajectory.txt"][2] - row["base", "trajectory.txt"][2]
        deltas.append(delta)
        fell += delta < 0
        cells = [row[label, name] for name in ("trajectory.txt", "trajectory_refined.txt")
                 for label in ("base", "variant")]
        print(f"| {cell} | " + " | ".join(f"{a:.1f} ({b:.1f} / {c:.1f})" for a, b, c in cells) +
              f" | {delta:+.2f} | {row['base', 'lag']} / {row['variant', 'lag']} |")
    print(f"\nonline high-frequency part lower in {fell} of {len(deltas)} cells; median Δ "
          f"{statistics.median(deltas):+.2f} mm")


if __name__ == "__main__":
    main()
