#!/usr/bin/env python3
"""Frames per second of one sequence tracked through Python and through `pspslam run`.

    PYTHONPATH=build/python python3 python/benchmarks/speed_vs_cli.py SEQUENCE \
        --cli build/apps/pspslam --pairs 5

Each pair runs both back to back (the order alternates, so a machine that gets busier or quieter
during a pair favours neither), each in a fresh process, deterministic. Speed is what `pspslam
run` reports in stats.json: processed frames over the time from the first frame to the end of
shutdown (system construction and model loading excluded); the Python side times the same span.
Prints every pair, the medians and the ratio Python / CLI.
"""

import argparse
import json
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
print(frames / (time.perf_counter() - start))
"""


def cli_fps(cli, sequence):
    with tempfile.TemporaryDirectory() as out:
        subprocess.run([cli, "-q", "run", "--sequence", sequence, "--out", out], check=True,
                       stdout=subprocess.DEVNULL)
        with open(f"{out}/stats.json") as stats:
            return json.load(stats)["fps"]


def python_fps(sequence):
    run = subprocess.run([sys.executable, "-c", PYTHON_RUN, sequence], check=True,
                         capture_output=True, text=True)
    return float(run.stdout.split()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequence")
    parser.add_argument("--cli", default="build/apps/pspslam")
    parser.add_argument("--pairs", type=int, default=5)
    args = parser.parse_args()
    cli_runs, python_runs = [], []
    for pair in range(args.pairs):
        started = time.strftime("%H:%M:%S")
        if pair % 2 == 0:
            c = cli_fps(args.cli, args.sequence)
            p = python_fps(args.sequence)
        else:
            p = python_fps(args.sequence)
            c = cli_fps(args.cli, args.sequence)
        cli_runs.append(c)
        python_runs.append(p)
        print(f"pair {pair + 1} ({started}): cli {c:.2f} fps, python {p:.2f} fps, "
              f"ratio {p / c:.3f}", flush=True)
    ratios = [p / c for p, c in zip(python_runs, cli_runs)]
    cli_median = statistics.median(cli_runs)
    python_median = statistics.median(python_runs)
    print(f"median: cli {cli_median:.2f} fps, python {python_median:.2f} fps; "
          f"ratio of medians {python_median / cli_median:.3f}, "
          f"median of pair ratios {statistics.median(ratios):.3f}")


if __name__ == "__main__":
    main()
