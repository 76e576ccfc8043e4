#!/usr/bin/python3
"""A long run, window by window (a minute at 30 Hz by default): the online and refined ATE, the
largest position error, the keyframes and map points in the map, resident memory and the
arrival-to-pose latency.

  tools/diagnosis/long_run.py RUN --sequence SEQ [--minute-frames 1800] [--plot OUT.png]
                              [--markdown OUT.md]

Each trajectory (RUN/trajectory.txt, RUN/trajectory_refined.txt) is aligned to the ground truth
once, by one SE(3) (no scale) over the whole run, and each window is then scored in that frame:
what a robot's map sees, drift included. (A runner stretch aligns each window on its own instead,
which hides drift between windows.) A window's ATE is the RMSE of the position errors of its
frames, its largest error their maximum. A pose meets the ground truth within 20 ms; where
SEQ/body_to_camera.txt exists the ground truth (the marker body) is moved to the camera by it.
Keyframes, map points and memory are the values at the window's last frame in RUN/timing.csv;
latency is the median and 99th percentile of its frames' arrival_to_pose_ms (empty in a run
without --realtime). Exit 2 with the file named on bad input."""
import argparse
import csv
import sys
from pathlib import Path

import numpy as np

MAX_TIME_DIFFERENCE = 0.02
TIMING_COLUMNS = ("index", "timestamp", "keyframes_in_map", "map_points", "rss_mib",
                  "arrival_to_pose_ms")


class InputError(Exception):
    """Bad or missing input; the message names the file."""


def quaternion_matrix(q):
    """Rotation matrices of TUM quaternions (qx, qy, qz, qw), one per row."""
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    x, y, z, w = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1),
    ], axis=1)


def read_tum(path):
    """(timestamps, positions, rotations) of a TUM trajectory file."""
    try:
        data = np.loadtxt(path, comments="#", ndmin=2)
    except (OSError, ValueError) as error:
        raise InputError(f"{path}: cannot read a TUM trajectory ({error})") from None
    if data.size == 0:
        return np.zeros(0), np.zeros((0, 3)), np.zeros((0, 3, 3))
    if data.shape[1] != 8:
        raise InputError(f"{path}: expected 8 columns (t tx ty tz qx qy qz qw), got "
                         f"{data.shape[1]}")
    return data[:, 0], data[:, 1:4], quaternion_matrix(data[:, 4:8])


def read_body_to_camera(path):
    """(R, t) of T_body_camera, 'tx ty tz qx qy qz qw' on one line."""
    try:
        rows = [line.split() for line in Path(path).read_text().splitlines()
                if line.strip() and not line.lstrip().startswith("#")]
        values = [float(v) for v in rows[0]] if len(rows) == 1 else None
    except (OSError, ValueError) as error:
        raise InputError(f"{path}: cannot read the transform ({error})") from None
    if values is None or len(values) != 7:
        raise InputError(f"{path}: expected one line 'tx ty tz qx qy qz qw'")
    return quaternion_matrix(np.array([values[3:]]))[0], np.array(values[:3])


def ground_truth_camera(sequence):
    """Timestamps and camera positions of the sequence's ground truth."""
    stamps, positions, rotations = read_tum(sequence / "groundtruth.txt")
    body = sequence / "body_to_camera.txt"
    if body.exists():
        _, t = read_body_to_camera(body)
        positions = positions + rotations @ t
    return stamps, positions


def read_timing(path):
    """The columns of timing.csv the report needs, as float arrays (NaN where empty)."""
    try:
        with open(path, newline="") as stream:
            rows = list(csv.reader(stream))
    except OSError as error:
        raise InputError(f"{path}: cannot read ({error})") from None
    if not rows:
        raise InputError(f"{path}: empty, expected a header line")
    missing = [name for name in TIMING_COLUMNS if name not in rows[0]]
    if missing:
        raise InputError(f"{path}: no column {', '.join(missing)} (a run of an older build?)")
    where = [rows[0].index(name) for name in TIMING_COLUMNS]
    columns = {name: [] for name in TIMING_COLUMNS}
    for line, row in enumerate(rows[1:], start=2):
        try:
            for name, k in zip(TIMING_COLUMNS, where):
                columns[name].append(float(row[k]) if row[k] else np.nan)
        except (IndexError, ValueError):
            raise InputError(f"{path}:{line}: expected {len(rows[0])} comma-separated "
                             "numbers") from None
    return {name: np.array(values) for name, values in columns.items()}


def associate(stamps, reference):
    """Index into `reference` (sorted) of each stamp's nearest time, -1 beyond 20 ms."""
    if len(reference) == 0:
        return np.full(len(stamps), -1)
    right = np.clip(np.searchsorted(reference, stamps), 1, len(reference) - 1)
    left = right - 1
    nearest = np.where(np.abs(reference[left] - stamps) <= np.abs(reference[right] - stamps),
                       left, right)
    if len(reference) == 1:
        nearest = np.zeros(len(stamps), dtype=int)
    return np.where(np.abs(reference[nearest] - stamps) <= MAX_TIME_DIFFERENCE, nearest, -1)


def align_se3(estimate, truth):
    """R, t minimising |R estimate + t - truth| (Umeyama without scale)."""
    mean_e, mean_t = estimate.mean(axis=0), truth.mean(axis=0)
    u, _, vt = np.linalg.svd((truth - mean_t).T @ (estimate - mean_e))
    d = np.eye(3)
    d[2, 2] = np.sign(np.linalg.det(u @ vt))
    rotation = u @ d @ vt
    return rotation, mean_t - rotation @ mean_e


def position_errors(path, frame_of_stamp, gt_stamps, gt_positions):
    """(frame index, position error m) of every pose of a trajectory file after one SE(3)
    alignment of the whole file to the ground truth."""
    stamps, positions, _ = read_tum(path)
    truth = associate(stamps, gt_stamps)
    frames = np.array([frame_of_stamp.get(round(s, 6), -1) for s in stamps], dtype=int)
    kept = (truth >= 0) & (frames >= 0)
    if kept.sum() < 3:
        return np.zeros(0, dtype=int), np.zeros(0)
    rotation, shift = align_se3(positions[kept], gt_positions[truth[kept]])
    moved = positions[kept] @ rotation.T + shift
    return frames[kept], np.linalg.norm(moved - gt_positions[truth[kept]], axis=1)


def window_rows(timing, online, refined, minute_frames):
    """One dict per window of `minute_frames` frames."""
    rows = []
    indices = timing["index"].astype(int)
    for first in range(0, int(indices.max()) + 1 if len(indices) else 0, minute_frames):
        last = first + minute_frames
        here = (indices >= first) & (indices < last)
        row = {"first": first, "last": min(last, int(indices.max()) + 1), "frames": int(here.sum())}
        for label, (frames, errors) in (("online", online), ("refined", refined)):
            inside = errors[(frames >= first) & (frames < last)]
            row[f"{label}_poses"] = int(inside.size)
            row[f"{label}_ate_mm"] = float(np.sqrt(np.mean(inside ** 2)) * 1e3) if inside.size else None
            row[f"{label}_max_mm"] = float(inside.max() * 1e3) if inside.size else None
        end = np.where(here)[0][-1]
        row["end_s"] = float(timing["timestamp"][end] - timing["timestamp"][0])
        for name in ("keyframes_in_map", "map_points", "rss_mib"):
            row[name] = float(timing[name][end])
        latency = timing["arrival_to_pose_ms"][here]
        latency = latency[~np.isnan(latency)]
        row["latency_p50_ms"] = float(np.percentile(latency, 50)) if latency.size else None
        row["latency_p99_ms"] = float(np.percentile(latency, 99)) if latency.size else None
        rows.append(row)
    return rows


def markdown(rows, minute_frames):
    def number(value, digits=1):
        return "–" if value is None else f"{value:.{digits}f}"
    lines = [f"| window (frames of {minute_frames}) | online ATE mm | online max mm | refined ATE mm"
             " | refined max mm | keyframes | map points | RSS MiB | latency p50 ms | p99 ms |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        lines.append(f"| {row['first']}–{row['last'] - 1} | {number(row['online_ate_mm'])} | "
                     f"{number(row['online_max_mm'])} | {number(row['refined_ate_mm'])} | "
                     f"{number(row['refined_max_mm'])} | {row['keyframes_in_map']:.0f} | "
                     f"{row['map_points']:.0f} | {number(row['rss_mib'])} | "
                     f"{number(row['latency_p50_ms'])} | {number(row['latency_p99_ms'])} |")
    return "\n".join(lines) + "\n"


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    minutes = [row["end_s"] / 60 for row in rows]
    figure, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    for label in ("online", "refined"):
        axes[0].plot(minutes, [row[f"{label}_ate_mm"] for row in rows], "o-", label=f"{label} ATE")
        axes[0].plot(minutes, [row[f"{label}_max_mm"] for row in rows], "x--", label=f"{label} max")
    axes[0].set_ylabel("position error (mm)")
    axes[0].legend()
    axes[1].plot(minutes, [row["keyframes_in_map"] for row in rows], "o-")
    axes[1].set_ylabel("keyframes in map")
    axes[2].plot(minutes, [row["rss_mib"] for row in rows], "o-")
    axes[2].set_ylabel("resident memory (MiB)")
    axes[2].set_xlabel("time at the window's last frame (min)")
    figure.tight_layout()
    figure.savefig(path)


def report(run, sequence, minute_frames):
    timing = read_timing(run / "timing.csv")
    if len(timing["index"]) == 0:
        raise InputError(f"{run / 'timing.csv'}: no frame rows")
    gt_stamps, gt_positions = ground_truth_camera(sequence)
    order = np.argsort(gt_stamps)
    gt_stamps, gt_positions = gt_stamps[order], gt_positions[order]
    frame_of_stamp = {round(float(t), 6): int(i) for i, t in zip(timing["index"],
                                                                 timing["timestamp"])}
    errors = [position_errors(run / name, frame_of_stamp, gt_stamps, gt_positions)
              for name in ("trajectory.txt", "trajectory_refined.txt")]
    return window_rows(timing, errors[0], errors[1], minute_frames)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("run", type=Path, help="the run's output folder")
    parser.add_argument("--sequence", required=True, type=Path,
                        help="the sequence folder (groundtruth.txt, body_to_camera.txt)")
    parser.add_argument("--minute-frames", type=int, default=1800,
                        help="frames in a window (default 1800: a minute at 30 Hz)")
    parser.add_argument("--plot", type=Path, help="write a plot of error, keyframes and memory")
    parser.add_argument("--markdown", type=Path, help="write the table to this file")
    args = parser.parse_args(argv)
    if args.minute_frames < 1:
        parser.error(f"--minute-frames: must be at least 1, got {args.minute_frames}")
    try:
        rows = report(args.run, args.sequence, args.minute_frames)
    except InputError as error:
        print(f"long_run.py: {error}", file=sys.stderr)
        return 2
    table = markdown(rows, args.minute_frames)
    print(table, end="")
    if args.markdown:
        args.markdown.write_text(table)
    if args.plot:
        plot(rows, args.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
