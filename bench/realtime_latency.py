#!/usr/bin/python3
"""Issue #18 item 1's figures: `pspslam run --realtime` N times on one sequence, each run's
frames processed, tracked, arrival-to-pose latency (median, p99), mask age (median), network
time, fps and ATE (online and refined) from its stats.json, then the median of each over the
runs. Usage: bench/realtime_latency.py [BUILD_DIR] [--runs N] [--dynamic MODE] [--sequence DIR]
[--config FILE] [--variant NAME='RUN FLAGS' ...]. With variants, run k of every variant is made
before run k+1 of any (interleaved, so a change in the machine's load hits all of them alike),
and each variant gets its medians; a variant's flags may start with ENV=VALUE words, which go
into that run's environment (e.g. OPENCV_FOR_THREADS_NUM=1). Run it on a quiet machine:
--realtime drops what the machine cannot keep up with.
"""
import argparse
import json
import os
import shlex
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

root = Path(__file__).resolve().parent.parent
shared = Path(os.environ.get("PSPSLAM_SHARED", root.parent / "shared"))


def figures(stats):
    latency = stats["latency"]
    return {
        "processed": stats["frames"],
        "tracked": stats["frames"] - stats["lost_frames"],
        "dropped": stats["realtime_dropped_frames"],
        "pose_p50_ms": latency["arrival_to_pose_ms"]["median"],
        "pose_p99_ms": latency["arrival_to_pose_ms"]["p99"],
        "mask_age_p50": latency["mask_age_frames"]["median"],
        "network_p50_ms": stats["timing_ms"]["semantic"]["median"],
        "fps": stats["fps"],
        "ate_online_mm": 1000 * stats["ate"]["rmse"] if "ate" in stats else float("nan"),
        "ate_refined_mm":
            1000 * stats["ate_refined"]["rmse"] if "ate_refined" in stats else float("nan"),
    }


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("build", nargs="?", default=str(root / "build"))
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--dynamic", default="full")
    parser.add_argument("--sequence", default=str(shared / "data/bonn_crowd_dev"))
    parser.add_argument("--config", default=str(root / "config/bonn.yaml"))
    parser.add_argument("--variant", action="append", default=[],
                        help="NAME='[ENV=VALUE ...] extra run flags' (repeatable)")
    args = parser.parse_args()
    variants = {"": []}
    if args.variant:
        variants = {}
        for spec in args.variant:
            name, _, flags = spec.partition("=")
            variants[name] = shlex.split(flags)
    cli = Path(args.build) / "apps/pspslam"
    work = Path(tempfile.mkdtemp(prefix="realtime_latency_"))
    print(f"# {time.strftime('%Y-%m-%d %H:%M:%S', time.gmtime())} UTC, load {os.getloadavg()}")
    rows = {name: [] for name in variants}
    for run in range(args.runs):
        for name, words in variants.items():
            env = dict(os.environ)
            while words and "=" in words[0] and not words[0].startswith("-"):
                key, _, value = words[0].partition("=")
                env[key] = value
                words = words[1:]
            out = work / f"{name or 'run'}{run}"
            command = [str(cli), "run", "--sequence", args.sequence, "--dynamic", args.dynamic,
                       "--realtime", "--quiet", "--out", str(out)] + words
            if args.config:
                command += ["--config", args.config]
            subprocess.run(command, check=True, env=env)
            row = figures(json.loads((out / "stats.json").read_text()))
            rows[name].append(row)
            print(f"{name + ' ' if name else ''}run {run}: "
                  + ", ".join(f"{k} {v:.1f}" if isinstance(v, float) else f"{k} {v}"
                              for k, v in row.items())
                  + f", load {os.getloadavg()[0]:.2f}", flush=True)
    for name, runs in rows.items():
        print(f"{name + ' ' if name else ''}median: "
              + ", ".join(f"{k} {statistics.median(r[k] for r in runs):.1f}" for k in runs[0]))
    print(f"# end {time.strftime('%Y-%m-%d %H:%M:%S', time.gmtime())} UTC, load {os.getloadavg()}")
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
