#!/usr/bin/env python3
"""The accuracy panel (issue #15): a variant against a baseline on a fixed panel of cells, both
run in the same invocation, judged by paired differences instead of one clip.

usage: bench/accuracy_panel.py [--variant-flags "..."] [--variant-sed EXPR] [--variant-build DIR]
                               [--base-flags "..."] [--base-sed EXPR] [--base-build DIR]
                               [--mode full] [--cells dev,synth] [--jobs 2] [--work DIR]
                               [--no-spread] [--title TEXT] [--synth-sensor ideal|kinect]
                               [--base-only | --reuse-base WORK]

A variant is extra `pspslam run` flags, a sed expression applied to every cell's camera config,
another build folder (a branch built elsewhere), or any mix; so is the baseline (default: this
checkout's build/, no flags). With no variant option the variant is the baseline itself, which
measures how far two identical configurations can differ (they should not: runs are deterministic).

Cells (one `pspslam run` each, per variant):
  dev            ../shared/data/bonn_crowd_dev whole, evaluated whole and also as its person-free
                 stretch (frames 0-217) and its crowd stretch (218-399), each aligned on its own
  dev_from_N     the clip started at frame N (N = 30, 90, 150)
  dev_jpeg80     the colour re-encoded as JPEG quality 80 (build/bench/reencode_colour)
  dev_depth_F    depth factor F = 4999 and 5001 instead of 5000 (a meaningless change)
  synth_S        six synthetic sequences (`pspslam synth`: seeds, people, hand-held or loop motion)
                 rendered with --synth-sensor (default ideal; kinect: a Kinect v1's faults, with a
                 marker-body ground truth that is moved onto the camera by its body_to_camera.txt;
                 cells named synth_..._kinect). Kinect cells err like real recordings do; ideal
                 ones by ~3 mm.
Each cell's spread is how far the baseline moves under a meaningless perturbation of that cell
(the depth factor one unit up, one more baseline run): a variant that loses by less than the
spread has not lost. A variant is worth adopting when it wins on most cells and loses by more than
the spread nowhere.

Per cell and file (trajectory.txt = online, trajectory_refined.txt = final) the ATE RMSE (SE(3),
Sim(3) for a monocular run; `pspslam eval`), the tracked frames, and whether the keyframes after
BA (keyframes.txt) are closer to the ground truth than the online poses of the same frames. Writes
WORK/panel.md and WORK/panel.json; existing runs in WORK are reused, so an interrupted panel
resumes; each run's job.json records the binary's SHA-256, the sequence, config and flags, and a
run made by anything else stops the panel with the folder named (delete it, or give another WORK,
after a rebuild). --base-only runs the baseline and spread runs alone (no variant, no table);
--reuse-base WORK links those runs of another WORK (same baseline build, flags and cells) into
this one instead of running them again, so a variant costs a third of the runs. Runs are
deterministic (a variant identical to the baseline gives byte-identical trajectories; since the
fifteenth session also where a loop closes), so a linked baseline is the baseline this invocation
would have run. Needs only the Python standard library.
"""
import argparse
import concurrent.futures
import hashlib
import json
import os
import re
import shlex
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PERSON_FREE_END = 218  # bonn_crowd_dev: nobody in view before this frame (shared/README.md)
DEV_STARTS = (30, 90, 150)
# (seed, people, trajectory): different rooms (the seed draws the textures and the walkers),
# crowds and motions.
SYNTH_CELLS = ((21, 2, "handheld"), (22, 3, "handheld"), (23, 4, "handheld"),
               (24, 3, "loop"), (25, 2, "loop"), (26, 4, "handheld"))
SYNTH_FRAMES = 240


def log(message):
    print(f"[{time.strftime('%H:%M:%S')}] {message}", file=sys.stderr, flush=True)


def read_list(path):
    """Lines of a TUM list file: (comment lines, data lines)."""
    comments, rows = [], []
    for line in Path(path).read_text().splitlines():
        (comments if line.startswith("#") or not line.strip() else rows).append(line)
    return comments, rows


def slice_sequence(source, target, first, last):
    """A TUM folder of colour frames first..last-1 of `source` (by rgb.txt order), with the depth
    and ground truth of that time span; images are linked, not copied."""
    target.mkdir(parents=True, exist_ok=True)
    comments, rgb = read_list(source / "rgb.txt")
    rgb = rgb[first:last]
    t0, t1 = float(rgb[0].split()[0]) - 0.05, float(rgb[-1].split()[0]) + 0.05
    (target / "rgb.txt").write_text("\n".join(comments + rgb) + "\n")
    for name in ("depth.txt", "groundtruth.txt"):
        comments, rows = read_list(source / name)
        rows = [r for r in rows if t0 <= float(r.split()[0]) <= t1]
        (target / name).write_text("\n".join(comments + rows) + "\n")
    for folder in ("rgb", "depth"):
        link = target / folder
        if not link.exists():
            link.symlink_to((source / folder).resolve())


def stretch_ground_truth(source, target, first, last):
    """The ground truth of colour frames first..last-1 only: evaluating against it aligns and
    scores that stretch of a longer run on its own."""
    _, rgb = read_list(source / "rgb.txt")
    t0 = float(rgb[first].split()[0]) - 0.02
    t1 = float(rgb[min(last, len(rgb)) - 1].split()[0]) + 0.02
    comments, rows = read_list(source / "groundtruth.txt")
    target.write_text("\n".join(comments + [r for r in rows if t0 <= float(r.split()[0]) <= t1])
                      + "\n")


def set_depth_factor(config_text, factor):
    text, count = re.subn(r"(depth_factor:\s*)[0-9.eE+-]+", rf"\g<1>{factor}", config_text)
    if count != 1:
        raise SystemExit("error: the config has no single 'depth_factor:' key")
    return text


def depth_factor(config_text):
    return float(re.search(r"depth_factor:\s*([0-9.eE+-]+)", config_text).group(1))


class Cell:
    def __init__(self, name, sequence, config_text, stretches, body_to_camera=None):
        self.name = name
        self.sequence = sequence
        self.config_text = config_text
        # (evaluation name, ground-truth file) pairs; the first is the whole cell.
        self.stretches = stretches
        # `pspslam eval --gt-body-to-camera` file when the ground truth is a marker body.
        self.body_to_camera = body_to_camera


def prepare_cells(args, work, cli):
    shared = Path(os.environ.get("PSPSLAM_SHARED", ROOT.parent / "shared"))
    dev = shared / "data" / "bonn_crowd_dev"
    cells = []
    kinds = set(args.cells.split(","))
    if "dev" in kinds:
        if not dev.is_dir():
            raise SystemExit(f"error: {dev} not found (set PSPSLAM_SHARED or --cells synth)")
        bonn = (ROOT / "config" / "bonn.yaml").read_text()
        free, crowd = work / "cells" / "dev_person_free_gt.txt", work / "cells" / "dev_crowd_gt.txt"
        free.parent.mkdir(parents=True, exist_ok=True)
        stretch_ground_truth(dev, free, 0, PERSON_FREE_END)
        stretch_ground_truth(dev, crowd, PERSON_FREE_END, 10**9)
        cells.append(Cell("dev", dev, bonn, [("dev", dev / "groundtruth.txt"),
                                             ("dev_person_free", free), ("dev_crowd", crowd)]))
        n = len(read_list(dev / "rgb.txt")[1])
        for start in DEV_STARTS:
            folder = work / "cells" / f"dev_from_{start}"
            slice_sequence(dev, folder, start, n)
            cells.append(Cell(f"dev_from_{start}", folder, bonn,
                              [(f"dev_from_{start}", folder / "groundtruth.txt")]))
        jpeg = work / "cells" / "dev_jpeg80"
        if not (jpeg / "rgb.txt").exists():
            tool = Path(args.base_build) / "bench" / "reencode_colour"
            subprocess.run([str(tool), str(dev), str(jpeg), "80"], check=True,
                           stdout=subprocess.DEVNULL)
        cells.append(Cell("dev_jpeg80", jpeg, bonn, [("dev_jpeg80", dev / "groundtruth.txt")]))
        base_factor = depth_factor(bonn)
        for delta in (-1, 1):
            factor = int(base_factor + delta)
            cells.append(Cell(f"dev_depth_{factor}", dev, set_depth_factor(bonn, factor),
                              [(f"dev_depth_{factor}", dev / "groundtruth.txt")]))
    if "synth" in kinds:
        for seed, people, motion in SYNTH_CELLS:
            name = f"synth_{seed}_{motion}_{people}p"
            if args.synth_sensor != "ideal":
                name += f"_{args.synth_sensor}"
            folder = work / "cells" / name
            if not (folder / "groundtruth.txt").exists():
                command = [str(cli), "-q", "synth", "--out", str(folder), "--frames",
                           str(SYNTH_FRAMES), "--bodies", str(people), "--seed", str(seed),
                           "--trajectory", motion, "--sensor", args.synth_sensor]
                if motion == "loop":
                    command += ["--loop-turns", "1.5"]
                subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
            body = folder / "body_to_camera.txt"
            cells.append(Cell(name, folder, (folder / "config.yaml").read_text(),
                              [(name, folder / "groundtruth.txt")],
                              body if body.exists() else None))
    return cells


def apply_sed(text, expression):
    if not expression:
        return text
    return subprocess.run(["sed", "-e", expression], input=text, capture_output=True, text=True,
                          check=True).stdout


def evaluate(cli, ground_truth, estimate, body_to_camera=None, sim3=False):
    """ATE RMSE (m) and pose count, or (None, 0) when nothing could be associated. `sim3`: align
    with scale (a monocular run), also for files away from the run's stats.json, which is what
    `pspslam eval` would otherwise read it from."""
    if not estimate.exists() or estimate.stat().st_size == 0:
        return None, 0
    command = [str(cli), "-q", "eval", "--gt", str(ground_truth), "--est", str(estimate), "--json"]
    if sim3:
        command.append("--sim3")
    if body_to_camera:
        command += ["--gt-body-to-camera", str(body_to_camera)]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        return None, 0
    error = json.loads(result.stdout)["ate"]["error_m"]
    return error["rmse"], error["count"]


def poses_at_stamps(trajectory, stamps_file, target):
    stamps = {line.split()[0] for line in stamps_file.read_text().splitlines()
              if line.strip() and not line.startswith("#")}
    rows = [line for line in trajectory.read_text().splitlines()
            if line.strip() and not line.startswith("#") and line.split()[0] in stamps]
    target.write_text("\n".join(rows) + "\n")


def file_sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def job_identity(job, cli_sha256):
    """What makes a run what it is: the binary, the sequence, the config and the flags (not the
    output folder, so that a baseline linked from another WORK is recognised)."""
    _, cell, config_text, flags, out, mode = job
    # A cell made inside WORK (a slice, a re-encoding, a synthetic sequence) is named relative to
    # it: the same cell of another WORK is the same sequence.
    work = out.parents[2]
    sequence = (f"WORK/{cell.sequence.relative_to(work)}" if cell.sequence.is_relative_to(work)
                else str(cell.sequence))
    return {"pspslam_sha256": cli_sha256, "sequence": sequence,
            "config_sha256": hashlib.sha256(config_text.encode()).hexdigest(),
            "dynamic": mode, "flags": flags}


def check_reusable(job, identity):
    """A run already in WORK is reused only when the same binary made it with the same sequence,
    config and flags; anything else (a rebuild, an old WORK, a baseline linked from a WORK of
    another build) stops the panel instead of being compared as if it were this invocation's."""
    out = job[4]
    if not (out / "stats.json").exists():
        return None
    recorded = out / "job.json"
    if not recorded.exists():
        return f"{out} holds a run without job.json (made by an older panel)"
    made = json.loads(recorded.read_text())
    differs = [key for key, value in identity.items() if made.get(key) != value]
    if differs:
        return f"{out} holds a run that differs in {' / '.join(differs)}"
    return None


def run_one(job, identity):
    """One `pspslam run` of a cell by one variant (or the baseline's spread run); skipped when
    its stats.json exists (checked by check_reusable first). Returns the measurements of every
    evaluation stretch."""
    cli, cell, config_text, flags, out, mode = job
    stats = out / "stats.json"
    if not stats.exists():
        out.mkdir(parents=True, exist_ok=True)
        config = out / "config.yaml"
        config.write_text(config_text)
        command = [str(cli), "-q", "run", "--sequence", str(cell.sequence), "--config",
                   str(config), "--out", str(out / "run"), "--dynamic", mode] + flags
        started = time.time()
        result = subprocess.run(command, capture_output=True, text=True)
        (out / "log.txt").write_text(" ".join(map(shlex.quote, command)) + "\n" + result.stdout +
                                     result.stderr)
        if result.returncode not in (0, 3):
            raise RuntimeError(f"{' '.join(command)} exited {result.returncode}; see {out}/log.txt")
        run_stats = json.loads((out / "run" / "stats.json").read_text())
        run_stats["panel_wall_s"] = time.time() - started
        stats.write_text(json.dumps(run_stats))
        (out / "job.json").write_text(json.dumps(identity, indent=1))
        log(f"{out.relative_to(out.parents[2])}: {run_stats['panel_wall_s']:.0f} s")
    run_stats = json.loads(stats.read_text())
    run = out / "run"
    results = {}
    sim3 = run_stats.get("sensor") == "monocular"
    for name, ground_truth in cell.stretches:
        body = cell.body_to_camera
        online, tracked = evaluate(cli, ground_truth, run / "trajectory.txt", body, sim3)
        final, _ = evaluate(cli, ground_truth, run / "trajectory_refined.txt", body, sim3)
        keyframes, keyframe_count = evaluate(cli, ground_truth, run / "keyframes.txt", body, sim3)
        online_at_keyframes = None
        if keyframe_count:
            subset = out / f"online_at_keyframes_{name}.txt"
            poses_at_stamps(run / "trajectory.txt", run / "keyframes.txt", subset)
            online_at_keyframes, _ = evaluate(cli, ground_truth, subset, body, sim3)
        results[name] = {"online": online, "final": final, "tracked": tracked,
                         "frames": run_stats["frames"], "keyframes": keyframes,
                         "online_at_keyframes": online_at_keyframes,
                         "keyframe_count": keyframe_count}
    return results


def mm(value):
    return "—" if value is None else f"{value * 1000:.1f}"


def summarise(cells, base, variant, spread, args):
    """Markdown tables and the verdict; returns (markdown, json-able summary)."""
    names = [name for cell in cells for name, _ in cell.stretches]
    lines = [f"# Accuracy panel: {args.title}", "",
             f"mode `{args.mode}`; baseline: build `{args.base_build}`, flags "
             f"`{args.base_flags or '(none)'}`, sed `{args.base_sed or '(none)'}`; variant: build "
             f"`{args.variant_build}`, flags `{args.variant_flags or '(none)'}`, sed "
             f"`{args.variant_sed or '(none)'}`. ATE RMSE in mm (SE(3); Sim(3) for monocular "
             f"runs); tracked = frames with a "
             f"pose evaluated / frames processed; KF = keyframes after BA vs the online poses of "
             f"the same frames (mm); spread = |baseline − baseline with the depth factor one "
             f"unit up|.", "",
             "| cell | base online | base final | var online | var final | tracked base/var | "
             "KF base (BA vs online) | KF var (BA vs online) | spread final | Δ final | verdict |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    summary = {"cells": {}, "title": args.title}
    wins = losses = bad_losses = 0
    deltas = {"online": [], "final": []}
    for name in names:
        b, v, s = base[name], variant[name], spread.get(name)
        spread_final = (abs(b["final"] - s["final"]) if s and s["final"] is not None
                        and b["final"] is not None else None)
        delta = None
        verdict = "—"
        if b["final"] is not None and v["final"] is not None:
            delta = v["final"] - b["final"]
            deltas["final"].append(delta)
            if delta < 0:
                wins += 1
                verdict = "win"
            elif delta > 0:
                losses += 1
                verdict = "loss"
                if spread_final is not None and delta > spread_final:
                    bad_losses += 1
                    verdict = "**loss > spread**"
            else:
                verdict = "tie"
        if b["online"] is not None and v["online"] is not None:
            deltas["online"].append(v["online"] - b["online"])
        lines.append(
            f"| {name} | {mm(b['online'])} | {mm(b['final'])} | {mm(v['online'])} | "
            f"{mm(v['final'])} | {b['tracked']}/{b['frames']} · {v['tracked']}/{v['frames']} | "
            f"{mm(b['keyframes'])} vs {mm(b['online_at_keyframes'])} | "
            f"{mm(v['keyframes'])} vs {mm(v['online_at_keyframes'])} | {mm(spread_final)} | "
            f"{'—' if delta is None else f'{delta * 1000:+.2f}'} | {verdict} |")
        summary["cells"][name] = {"base": b, "variant": v, "spread": s,
                                  "spread_final": spread_final, "delta_final": delta}

    def column(runs, key):
        return [runs[n][key] for n in names if runs[n][key] is not None]

    def stat_line(label, values):
        if not values:
            return f"| {label} | — | — | — |"
        return (f"| {label} | {statistics.median(values) * 1000:.1f} | "
                f"{min(values) * 1000:.1f} | {max(values) * 1000:.1f} |")

    dev_names = [n for n in names if n.startswith("dev") and n not in
                 ("dev_person_free", "dev_crowd")]
    lines += ["", "| over cells | median | min | max |", "|---|---|---|---|"]
    for label, runs in (("baseline", base), ("variant", variant)):
        for key in ("online", "final"):
            lines.append(stat_line(f"{label} {key}, all cells", column(runs, key)))
            if dev_names:
                lines.append(stat_line(f"{label} {key}, dev-clip cells (whole clip, starts, "
                                       "re-encoding, depth factors)",
                                       [runs[n][key] for n in dev_names
                                        if runs[n][key] is not None]))
    kf_better = {label: sum(1 for n in names if runs[n]["keyframes"] is not None and
                            runs[n]["online_at_keyframes"] is not None and
                            runs[n]["keyframes"] < runs[n]["online_at_keyframes"])
                 for label, runs in (("baseline", base), ("variant", variant))}
    final_not_worse = {label: sum(1 for n in names if runs[n]["final"] is not None and
                                  runs[n]["online"] is not None and
                                  runs[n]["final"] <= runs[n]["online"])
                       for label, runs in (("baseline", base), ("variant", variant))}
    median_delta = statistics.median(deltas["final"]) if deltas["final"] else None
    median_online = statistics.median(deltas["online"]) if deltas["online"] else None
    adopt = wins > len(deltas["final"]) / 2 and bad_losses == 0

    def signed_mm(value):
        return "—" if value is None else f"{value * 1000:+.1f}"

    lines += ["",
              f"- paired, final trajectory: variant wins {wins}, loses {losses} "
              f"({bad_losses} by more than the cell's spread), ties "
              f"{len(deltas['final']) - wins - losses} of {len(deltas['final'])} cells; "
              f"median Δ {signed_mm(median_delta)} mm (online: median Δ "
              f"{signed_mm(median_online)} mm)",
              f"- keyframes after BA closer to the ground truth than the online poses: baseline "
              f"{kf_better['baseline']}/{len(names)} cells, variant {kf_better['variant']}/"
              f"{len(names)}",
              f"- final trajectory not worse than the online one: baseline "
              f"{final_not_worse['baseline']}/{len(names)}, variant "
              f"{final_not_worse['variant']}/{len(names)}",
              f"- verdict: **{'adopt' if adopt else 'do not adopt'}** (adopt = wins on most cells "
              f"and no loss beyond the cell's spread)"]
    summary.update({"wins": wins, "losses": losses, "losses_beyond_spread": bad_losses,
                    "median_delta_final": median_delta, "adopt": adopt,
                    "keyframes_better_than_online": kf_better,
                    "final_not_worse_than_online": final_not_worse})
    return "\n".join(lines) + "\n", summary


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--variant-flags", default="")
    parser.add_argument("--variant-sed", default="")
    parser.add_argument("--variant-build", default=None)
    parser.add_argument("--base-flags", default="")
    parser.add_argument("--base-sed", default="")
    parser.add_argument("--base-build", default=str(ROOT / "build"))
    parser.add_argument("--mode", default="full",
                        choices=["off", "semantic", "geometry", "full", "exhaustive"])
    parser.add_argument("--cells", default="dev,synth")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--work", default="/tmp/pspslam_panel")
    parser.add_argument("--no-spread", action="store_true",
                        help="skip the baseline's spread runs (no 'loss > spread' verdicts)")
    parser.add_argument("--title", default="")
    parser.add_argument("--base-only", action="store_true",
                        help="run only the baseline and its spread runs (for --reuse-base)")
    parser.add_argument("--reuse-base", default=None,
                        help="link the baseline and spread runs of this earlier --work folder")
    parser.add_argument("--synth-sensor", default="ideal", choices=["ideal", "kinect"],
                        help="`pspslam synth --sensor` of the synth cells")
    args = parser.parse_args()
    args.variant_build = args.variant_build or args.base_build
    args.title = args.title or (args.variant_flags or args.variant_sed or args.variant_build)
    if not set(args.cells.split(",")) <= {"dev", "synth"}:
        parser.error("--cells: a comma-separated list of dev, synth")
    work = Path(args.work).resolve()
    clis = {}
    for label in ("base", "variant"):
        cli = Path(getattr(args, f"{label}_build")).resolve() / "apps" / "pspslam"
        if not os.access(cli, os.X_OK):
            parser.error(f"{cli} is not built (cmake --build BUILD --target pspslam_cli)")
        clis[label] = cli
    cells = prepare_cells(args, work, clis["base"])

    linked = 0
    if args.reuse_base:
        for cell in cells:
            for label in ("base", "spread"):
                source = Path(args.reuse_base).resolve() / "runs" / cell.name / label
                target = work / "runs" / cell.name / label
                if (source / "stats.json").exists() and not target.exists():
                    target.parent.mkdir(parents=True, exist_ok=True)
                    target.symlink_to(source, target_is_directory=True)
                if target.is_symlink() and target.resolve() == source:
                    linked += 1
    jobs, keys = [], []
    for cell in cells:
        base_config = apply_sed(cell.config_text, args.base_sed)
        jobs.append((clis["base"], cell, base_config, shlex.split(args.base_flags),
                     work / "runs" / cell.name / "base", args.mode))
        keys.append(("base", cell))
        if not args.base_only:
            jobs.append((clis["variant"], cell, apply_sed(cell.config_text, args.variant_sed),
                         shlex.split(args.variant_flags), work / "runs" / cell.name / "variant",
                         args.mode))
            keys.append(("variant", cell))
        if not args.no_spread:
            jittered = set_depth_factor(base_config, int(depth_factor(base_config) + 1))
            jobs.append((clis["base"], cell, jittered, shlex.split(args.base_flags),
                         work / "runs" / cell.name / "spread", args.mode))
            keys.append(("spread", cell))
    hashes = {cli: file_sha256(cli) for cli in set(clis.values())}
    identities = [job_identity(job, hashes[job[0]]) for job in jobs]
    stale = [problem for job, identity in zip(jobs, identities)
             if (problem := check_reusable(job, identity))]
    if stale:
        sys.exit(f"accuracy_panel.py: {stale[0]} ({len(stale)} such runs); delete them or give "
                 "another --work (or --reuse-base a WORK of this baseline)")
    log(f"{len(jobs)} runs of {len(cells)} cells in {work} ({args.jobs} at a time)")
    started = time.time()
    results = {"base": {}, "variant": {}, "spread": {}}
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for (label, _), measured in zip(keys, pool.map(run_one, jobs, identities)):
            results[label].update(measured)
    if args.base_only:
        log(f"baseline and spread runs done in {work}")
        return
    markdown, summary = summarise(cells, results["base"], results["variant"], results["spread"],
                                  args)
    load = os.getloadavg()
    reused = f" ({linked} linked from {args.reuse_base})" if linked else ""
    markdown += (f"\n_{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {len(jobs)} runs"
                 f"{reused} in {(time.time() - started) / 60:.1f} min, {args.jobs} at a time, load "
                 f"{load[0]:.1f}; command: `{' '.join(map(shlex.quote, sys.argv))}`_\n")
    (work / "panel.md").write_text(markdown)
    (work / "panel.json").write_text(json.dumps(summary, indent=1))
    print(markdown)


if __name__ == "__main__":
    main()
