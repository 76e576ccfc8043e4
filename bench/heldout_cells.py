#!/usr/bin/env python3
"""Two configs on perturbations of bonn_crowd_dev that the accuracy panel does not use.

usage: bench/heldout_cells.py BASE.yaml VARIANT.yaml [--build build] [--mode full] [--jobs 2]
       [--work /tmp/pspslam_heldout]

A default chosen on the panel's cells (bench/accuracy_panel.py) has seen them; these nine cells
it has not: the clip's first 200 and 300 frames, the clip started at frames 60, 120 and 200,
colour re-encoded at JPEG quality 60 and 90, depth factors 4998 and 5002. Each cell runs both
configs with the same binary (`pspslam run --dynamic MODE`, deterministic) and prints ATE RMSE
(mm, `pspslam eval`) of trajectory.txt (online) and trajectory_refined.txt (final), frames
evaluated, the paired differences and how many cells the variant lowers. Cells are prepared
once in --work and kept. Needs ../shared (or $PSPSLAM_SHARED) and a build with pspslam_cli and
bench/reencode_colour.
"""
import argparse
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import accuracy_panel as panel  # noqa: E402


def prepare(dev, work, build):
    frames = len(panel.read_list(dev / "rgb.txt")[1])
    cells = []
    for first, last in ((0, 200), (0, 300), (60, frames), (120, frames), (200, frames)):
        folder = work / "cells" / f"frames_{first}_to_{last}"
        if not (folder / "rgb.txt").exists():
            panel.slice_sequence(dev, folder, first, last)
        cells.append((folder.name, folder, None))
    for quality in (60, 90):
        folder = work / "cells" / f"jpeg{quality}"
        if not (folder / "rgb.txt").exists():
            subprocess.run([str(build / "bench" / "reencode_colour"), str(dev), str(folder),
                            str(quality)], check=True, stdout=subprocess.DEVNULL)
        cells.append((folder.name, folder, None))
    for factor in (4998, 5002):
        cells.append((f"depth_{factor}", dev, factor))
    return cells


def ate(cli, ground_truth, estimate):
    output = subprocess.run([str(cli), "eval", "--gt", str(ground_truth), "--est", str(estimate)],
                            capture_output=True, text=True).stdout
    match = re.search(r"ATE\s+m\s+(\d+)\s+([0-9.]+)", output)
    if not match:
        raise SystemExit(f"error: no ATE from pspslam eval on {estimate}:\n{output}")
    return int(match.group(1)), float(match.group(2)) * 1000.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("base_config")
    parser.add_argument("variant_config")
    parser.add_argument("--build", default=str(panel.ROOT / "build"))
    parser.add_argument("--mode", default="full")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--work", default="/tmp/pspslam_heldout")
    args = parser.parse_args()
    shared = Path(os.environ.get("PSPSLAM_SHARED", panel.ROOT.parent / "shared"))
    dev = shared / "data" / "bonn_crowd_dev"
    if not dev.is_dir():
        raise SystemExit(f"error: {dev} not found (set PSPSLAM_SHARED)")
    build, work = Path(args.build), Path(args.work)
    cli = build / "apps" / "pspslam"
    if not os.access(cli, os.X_OK):
        raise SystemExit(f"error: {cli} is not built (cmake --build BUILD --target pspslam_cli)")
    configs = {"base": Path(args.base_config).read_text(),
               "variant": Path(args.variant_config).read_text()}
    cells = prepare(dev, work, build)

    def run(job):
        name, sequence, factor, label = job
        text = configs[label]
        if factor is not None:
            text = panel.set_depth_factor(text, factor)
        out = work / "runs" / name / label
        out.mkdir(parents=True, exist_ok=True)
        (out / "config.yaml").write_text(text)
        subprocess.run([str(cli), "-q", "run", "--sequence", str(sequence), "--config",
                        str(out / "config.yaml"), "--dynamic", args.mode, "--out",
                        str(out / "run")], check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        ground_truth = sequence / "groundtruth.txt"
        print(f"{name}/{label} done", file=sys.stderr, flush=True)
        return name, label, [ate(cli, ground_truth, out / "run" / f)
                             for f in ("trajectory.txt", "trajectory_refined.txt")]

    jobs = [(name, sequence, factor, label) for name, sequence, factor in cells
            for label in configs]
    with ThreadPoolExecutor(args.jobs) as pool:
        results = list(pool.map(run, jobs))
    table = {}
    for name, label, errors in results:
        table.setdefault(name, {})[label] = errors
    print("| cell | base: online / final (frames) | variant: online / final (frames) "
          "| Δ online | Δ final |")
    print("|---|---|---|---|---|")
    lower = [0, 0]
    for name, errors in table.items():
        base, variant = errors["base"], errors["variant"]
        deltas = [variant[k][1] - base[k][1] for k in (0, 1)]
        for k in (0, 1):
            lower[k] += deltas[k] < 0
        print(f"| {name} | {base[0][1]:.1f} / {base[1][1]:.1f} ({base[0][0]}) | "
              f"{variant[0][1]:.1f} / {variant[1][1]:.1f} ({variant[0][0]}) | "
              f"{deltas[0]:+.1f} | {deltas[1]:+.1f} |")
    print(f"\nvariant lower online in {lower[0]} of {len(table)} cells, final in {lower[1]} of "
          f"{len(table)} (mode {args.mode}, build {build})")


if __name__ == "__main__":
    main()
