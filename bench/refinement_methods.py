#!/usr/bin/env python3
"""Ways of making the final trajectory, compared on the runs of a finished accuracy panel.

usage: bench/refinement_methods.py WORK [--label base] [--cells NAME,...]

Rebuilds, from each run's trajectory.txt (online poses) and keyframes.txt (keyframe poses after
BA), alternative final trajectories and prints their ATE RMSE in mm (SE(3), positions, nearest
ground-truth pose within 20 ms, as `pspslam eval`), per cell of WORK/runs/<cell>/<label>:
  online       trajectory.txt as it is
  whole        every keyframe correction D = T_BA · T_tracked⁻¹ interpolated in time and applied
               whole (the final trajectory before this script's change; it reproduces the run's
               trajectory_refined.txt exactly when no loop closed: one map epoch)
  centred      the same corrections, each turning about its keyframe's tracked camera centre, so
               the interpolation does not depend on where the world origin lies
  g=0.25 ...   the same with fixed shares g of every correction (D^g: angle and translation × g)
  g=est        the share estimated from the corrections themselves, clamp(1 − σ²/var, 0, 1):
               σ² = mean |d_k+1 − d_k|² / 2 and var = mean |d_k − mean d|² over the keyframes'
               camera-centre shifts d_k (after BA − as tracked); the C++ of this variant is
               bench/patches/refine_gain.patch
  smooth S     the corrections smoothed by a Gaussian of S seconds over the keyframes first
  local-fit    corrections measured against a local quadratic fit of the tracked poses (±4
               frames) instead of the keyframe's own tracked pose
Loop closures are ignored (one map epoch), so cells where a loop closed are approximate.
Needs Debian's python3-numpy.
"""
import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import trajectory_error_bands as bands  # noqa: E402


def quaternion(r):
    w = np.sqrt(max(0.0, 1 + r[0, 0] + r[1, 1] + r[2, 2])) / 2
    x = np.copysign(np.sqrt(max(0.0, 1 + r[0, 0] - r[1, 1] - r[2, 2])) / 2, r[2, 1] - r[1, 2])
    y = np.copysign(np.sqrt(max(0.0, 1 - r[0, 0] + r[1, 1] - r[2, 2])) / 2, r[0, 2] - r[2, 0])
    z = np.copysign(np.sqrt(max(0.0, 1 - r[0, 0] - r[1, 1] + r[2, 2])) / 2, r[1, 0] - r[0, 1])
    q = np.array([x, y, z, w])
    return q / np.linalg.norm(q)


def matrix(row):
    t = np.eye(4)
    t[:3, :3] = bands.rotation(row[4:8])
    t[:3, 3] = row[1:4]
    return t


def row_of(stamp, t):
    return np.concatenate([[stamp], t[:3, 3], quaternion(t[:3, :3])])


def log_so3(r):
    angle = np.arccos(np.clip((np.trace(r) - 1) / 2, -1, 1))
    v = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    return v / 2 if angle < 1e-9 else v * angle / (2 * np.sin(angle))


def exp_so3(w):
    angle = np.linalg.norm(w)
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    if angle < 1e-12:
        return np.eye(3) + k
    return np.eye(3) + np.sin(angle) / angle * k + (1 - np.cos(angle)) / angle ** 2 * k @ k


def power(d, g):
    out = np.eye(4)
    out[:3, :3] = exp_so3(g * log_so3(d[:3, :3]))
    out[:3, 3] = g * d[:3, 3]
    return out


def keyframe_indices(online, keyframes):
    index = {round(t, 4): i for i, t in enumerate(online[:, 0])}
    return [(index[round(row[0], 4)], row) for row in keyframes if round(row[0], 4) in index]


def interpolate(online, corrections, centres=None):
    """corrections: [(stamp, D)] sorted; D interpolated in time (slerp, linear), applied on the
    left; ends take the nearest keyframe's D (src/pspslam/tracking/trajectory_refinement.cpp).
    centres: the keyframes' tracked camera centres c_k; then each D_k turns about c_k
    (x -> R_k (x - c_k) + D_k c_k), so a frame between keyframes a and b is turned by
    slerp(R_a, R_b) about the chord point (1 - s) c_a + s c_b, which moves to
    (1 - s) D_a c_a + s D_b c_b: the same at the keyframes, and independent of where the world
    origin lies in between (blending D's translations carries R_k times the keyframe's distance
    from the origin)."""
    stamps = np.array([c[0] for c in corrections])
    out = []
    for row in online:
        n = np.searchsorted(stamps, row[0] - 1e-9)
        if n == 0 or n == len(stamps):
            d = corrections[0 if n == 0 else -1][1]
        else:
            (ta, a), (tb, b) = corrections[n - 1], corrections[n]
            s = (row[0] - ta) / (tb - ta)
            d = np.eye(4)
            d[:3, :3] = a[:3, :3] @ exp_so3(s * log_so3(a[:3, :3].T @ b[:3, :3]))
            d[:3, 3] = (1 - s) * a[:3, 3] + s * b[:3, 3]
            if centres is not None:
                ca, cb = centres[n - 1], centres[n]
                moved = (1 - s) * (a[:3, :3] @ ca + a[:3, 3]) + s * (b[:3, :3] @ cb + b[:3, 3])
                d[:3, 3] = moved - d[:3, :3] @ ((1 - s) * ca + s * cb)
        out.append(row_of(row[0], d @ matrix(row)))
    return np.array(out)


def estimated_gain(online, keyframes):
    shifts = np.array([row[1:4] - online[i, 1:4] for i, row in keyframe_indices(online,
                                                                                   keyframes)])
    if len(shifts) < 3:
        return 1.0
    spread = ((shifts - shifts.mean(0)) ** 2).sum(1).mean()
    noise = (np.diff(shifts, axis=0) ** 2).sum(1).mean() / 2
    return 1.0 if spread <= 0 else float(np.clip(1 - noise / spread, 0, 1))


def local_fit(online, i, half):
    a, b = max(0, i - half), min(len(online), i + half + 1)
    r = bands.rotation(online[i, 4:8])
    x = online[a:b, 0] - online[i, 0]
    v = np.vander(x, 3)
    p = np.linalg.lstsq(v, online[a:b, 1:4], rcond=None)[0][-1]
    w = np.array([log_so3(r.T @ bands.rotation(online[j, 4:8])) for j in range(a, b)])
    w = np.linalg.lstsq(v, w, rcond=None)[0][-1]
    m = np.eye(4)
    m[:3, :3] = r @ exp_so3(w)
    m[:3, 3] = p
    return m


def methods(online, keyframes):
    pairs = keyframe_indices(online, keyframes)
    corrections = [(row[0], matrix(row) @ np.linalg.inv(matrix(online[i]))) for i, row in pairs]
    out = {"online": online, "whole": interpolate(online, corrections),
           "centred": interpolate(online, corrections, [online[i, 1:4] for i, _ in pairs])}
    for g in (0.25, 0.5, 0.75):
        out[f"g={g}"] = interpolate(online, [(t, power(d, g)) for t, d in corrections])
    g = estimated_gain(online, keyframes)
    out["g=est"] = interpolate(online, [(t, power(d, g)) for t, d in corrections])
    stamps = np.array([t for t, _ in corrections])
    r0 = corrections[0][1][:3, :3]
    w = np.array([log_so3(r0.T @ d[:3, :3]) for _, d in corrections])
    tr = np.array([d[:3, 3] for _, d in corrections])
    for sigma in (0.3, 1.0):
        smoothed = []
        for t in stamps:
            k = np.exp(-0.5 * ((stamps - t) / sigma) ** 2)
            k /= k.sum()
            d = np.eye(4)
            d[:3, :3] = r0 @ exp_so3(k @ w)
            d[:3, 3] = k @ tr
            smoothed.append((t, d))
        out[f"smooth {sigma}s"] = interpolate(online, smoothed)
    fitted = [(row[0], matrix(row) @ np.linalg.inv(local_fit(online, i, 4))) for i, row in pairs]
    out["local-fit"] = interpolate(online, fitted)
    return out, g


def ate_mm(ground_truth, estimate, body):
    gt = ground_truth.copy()
    if body is not None:
        gt[:, 1:4] += np.array([bands.rotation(q) @ body[0:3] for q in gt[:, 4:8]])
    nearest = np.array([np.argmin(np.abs(gt[:, 0] - t)) for t in estimate[:, 0]])
    keep = np.abs(gt[nearest, 0] - estimate[:, 0]) < 0.02
    p, g = estimate[keep, 1:4], gt[nearest[keep], 1:4]
    r, t = bands.align(p, g)
    return bands.rms(p @ r.T + t - g)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("work")
    parser.add_argument("--label", default="base")
    parser.add_argument("--cells", default="")
    args = parser.parse_args()
    runs = Path(args.work) / "runs"
    rows, header = [], None
    for cell in sorted(p.name for p in runs.iterdir()):
        if args.cells and cell not in args.cells.split(","):
            continue
        out = runs / cell / args.label
        command = (out / "log.txt").read_text().split("\n")[0].split()
        sequence = Path(command[command.index("--sequence") + 1])
        body = sequence / "body_to_camera.txt"
        body = bands.load(body)[0] if body.exists() else None
        ground_truth = bands.load(sequence / "groundtruth.txt")
        trajectories, gain = methods(bands.load(out / "run" / "trajectory.txt"),
                                     bands.load(out / "run" / "keyframes.txt"))
        errors = {name: ate_mm(ground_truth, t, body) for name, t in trajectories.items()}
        if header is None:
            header = list(errors)
            print("| cell | " + " | ".join(header) + " | estimated g |")
            print("|---|" + "---|" * (len(header) + 1))
        rows.append(errors)
        print(f"| {cell} | " + " | ".join(f"{errors[n]:.1f}" for n in header) + f" | {gain:.2f} |")
    if rows:
        print("| median | " + " | ".join(f"{np.median([r[n] for r in rows]):.1f}" for n in header) +
              " | |")
        print("| cells ≤ online | " + " | ".join(
            str(sum(r[n] <= r["online"] + 1e-9 for r in rows)) for n in header) + " | |")


if __name__ == "__main__":
    main()
