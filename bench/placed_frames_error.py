#!/usr/bin/env python3
"""Error of the frames a monocular map placed at its start (issue #16), against the frames tracked.

A monocular run's first PLACED poses in trajectory.txt are the frames before the map's start that
it placed (stats.json `monocular.placed_before_initialisation`). Two Sim(3) alignments (Umeyama,
positions associated within 0.02 s):
  global - aligned on the tracked frames only (the alignment the run without placed frames had):
           the placed frames' error there includes the map's scale drift at its start
  local  - aligned on the placed frames and the next 30 tracked frames: how well the placed frames
           agree with the map around them, next to those 30 tracked frames
Numpy and bench/tum_numpy.py only.

    /usr/bin/python3 bench/placed_frames_error.py SEQ/groundtruth.txt OUT/trajectory.txt PLACED
"""
import argparse

import numpy as np

from tum_numpy import load_positions, umeyama


def rms(errors):
    return 1e3 * float(np.sqrt(np.mean(np.square(errors))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("groundtruth")
    parser.add_argument("trajectory")
    parser.add_argument("placed", type=int, help="how many leading poses the map placed")
    args = parser.parse_args()
    truth, estimate = load_positions(args.groundtruth), load_positions(args.trajectory)
    truth_times = np.array(sorted(truth))
    pairs = []
    for index, time in enumerate(sorted(estimate)):
        nearest = truth_times[np.abs(truth_times - time).argmin()]
        if abs(nearest - time) < 0.02:
            pairs.append((index, estimate[time], truth[nearest]))
    placed = [p for p in pairs if p[0] < args.placed]
    tracked = [p for p in pairs if p[0] >= args.placed]
    if len(placed) < 1 or len(tracked) < 30:
        raise SystemExit(f"need placed frames and 30 tracked ones: {len(placed)}, {len(tracked)}")

    def errors(subset, fit):
        scale, rotation, offset = umeyama(np.array([p[1] for p in fit]), np.array([p[2] for p in fit]),
                                          with_scale=True)
        return [float(np.linalg.norm(scale * rotation @ p[1] + offset - p[2])) for p in subset]

    global_placed, global_tracked = errors(placed, tracked), errors(tracked, tracked)
    local = placed + tracked[:30]
    local_placed, local_next = errors(placed, local), errors(tracked[:30], local)
    print(f"global (aligned on the {len(tracked)} tracked): placed {len(placed)} RMS "
          f"{rms(global_placed):.1f} mm (max {1e3 * max(global_placed):.1f}), tracked "
          f"{rms(global_tracked):.1f} mm")
    print(f"local (aligned on the placed + the next 30 tracked): placed {rms(local_placed):.1f} mm, "
          f"next 30 tracked {rms(local_next):.1f} mm")


if __name__ == "__main__":
    main()
