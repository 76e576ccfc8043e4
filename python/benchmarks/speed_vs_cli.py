#!/usr/bin/env python3
"""Frames per second of one sequence tracked through Python and through `pspslam run`.

    PYTHONPATH=build/python python3 python/benchmarks/speed_vs_cli.py SEQUENCE \
        --cli build/apps/pspslam --pairs 5

Each pair runs both back to back (the order alternates, so a machine that gets busier or quieter
during a pair favours neither), each in a fresh process, deterministic. Speed is what `pspslam
run` reports in stats.json: processed frames over the time from the first frame to the end of
shutdown (system construction and model loading excluded); the Python side times the same span.
Beside that wall-clock speed, which on a shared, loaded machine swings with the load, each run's
process CPU time (user + system, all threads, model loading included) is recorded: frames per CPU
second hardly depends on what else runs. Prints every pair, the medians and the ratios
Python / CLI of both.
"""

import argparse
import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time

PYTHON_RUN = """
import sys, time
import pspslam
sequence = pspslam.read_sequence(sys.argv[1])
slam = pspslam.System(sequence)
start = time.perf_counter()
frames = 0
with slam:
    for frame, result in slam.track_frames(sequence):
        frames += 1
print(frames / (time.perf_counter() - start), frames)
"""


def children_cpu_seconds():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def cli_fps(cli, sequence):
    with tempfile.TemporaryDirectory() as out:
        subprocess.run([cli, "-q", "run", "--sequence", sequence, "--out", out], check=True,
                       stdout=subprocess.DEVNULL)
        with open(f"{out}/stats.json") as stats:
            stats = json.load(stats)
            return stats["fps"], stats["frames"]


def python_fps(sequence):
    run = subprocess.run([sys.executable, "-c", PYTHON_RUN, sequence], check=True,
                         capture_output=True, text=True)
    fps, frames = run.stdout.split()[-2:]
    return float(fps), int(frames)


def measured(run):
    """(wall-clock fps, frames per process CPU second) of one run."""
    cpu_before = children_cpu_seconds()
    fps, frames = run()
    return fps, frames / (children_cpu_seconds() - cpu_before)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequence")
    parser.add_argument("--cli", default="build/apps/pspslam")
    parser.add_argument("--pairs", type=int, default=5)
    args = parser.parse_args()
    runs = {"cli": [], "python": []}
    measure = {"cli": lambda: measured(lambda: cli_fps(args.cli, args.sequence)),
               "python": lambda: measured(lambda: python_fps(args.sequence))}
    for pair in range(args.pairs):
        started = time.strftime("%H:%M:%S")
        order = ["cli", "python"] if pair % 2 == 0 else ["python", "cli"]
        for side in order:
            runs[side].append(measure[side]())
        (c, c_cpu), (p, p_cpu) = runs["cli"][-1], runs["python"][-1]
        print(f"pair {pair + 1} ({started}): cli {c:.2f} fps {c_cpu:.2f} f/cpu-s, python "
              f"{p:.2f} fps {p_cpu:.2f} f/cpu-s; ratios wall {p / c:.3f}, cpu {p_cpu / c_cpu:.3f}",
              flush=True)
    for index, what in ((0, "wall-clock fps"), (1, "frames per CPU second")):
        cli = [run[index] for run in runs["cli"]]
        python = [run[index] for run in runs["python"]]
        ratios = [p / c for p, c in zip(python, cli)]
        print(f"{what}: median cli {statistics.median(cli):.2f}, python "
              f"{statistics.median(python):.2f}; ratio of medians "
              f"{statistics.median(python) / statistics.median(cli):.3f}, median of pair ratios "
              f"{statistics.median(ratios):.3f}")

if __name__ == "__main__":
    main()
