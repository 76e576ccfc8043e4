#!/usr/bin/python3
"""Could two maps of a run's atlas have merged? Place recognition needs a place both maps saw:
this tool looks for it in the ground truth. For every pair of maps in the run's stats.json
(`atlas.maps`: the frames each map tracked), it finds the frame of the later map that came
closest to a view of the earlier one, leaving out the frames within --seam-frames of the frame
where one map ended and the next began (there the views touch by construction, but the old map
was lost for lack of points). A view counts when the two optical axes differ by at most
--max-angle degrees; the answer is the smallest distance between such views, or none.

  tools/diagnosis/atlas_revisits.py --run RUN --sequence SEQ [--seam-frames 30] [--max-angle 20]

Reads RUN/stats.json and SEQ/groundtruth.txt (TUM: one pose per frame, in frame order, as
`pspslam synth` writes it). Exit 2 with the file named on bad input."""
import argparse
import json
import sys
from pathlib import Path

import numpy as np


class InputError(Exception):
    """Bad or missing input; the message names the file."""


def optical_axes(quaternions):
    """Camera z axes in the world of TUM quaternions (qx, qy, qz, qw), one per row."""
    x, y, z, w = quaternions.T
    return np.stack([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)], axis=1)


def read_ground_truth(path):
    try:
        data = np.loadtxt(path, comments="#", ndmin=2)
    except (OSError, ValueError) as error:
        raise InputError(f"{path}: cannot read a TUM trajectory ({error})") from None
    if data.shape[1] != 8:
        raise InputError(f"{path}: expected 8 columns (t tx ty tz qx qy qz qw), got "
                         f"{data.shape[1]}")
    return data[:, 1:4], optical_axes(data[:, 4:8])


def read_maps(path):
    try:
        stats = json.loads(Path(path).read_text())
    except (OSError, ValueError) as error:
        raise InputError(f"{path}: cannot read the run's stats.json ({error})") from None
    maps = stats.get("atlas", {}).get("maps")
    if not isinstance(maps, list):
        raise InputError(f"{path}: no atlas.maps (a run of a build without the atlas?)")
    return maps


def closest_revisit(positions, axes, earlier, later, seam_frames, max_angle):
    """(distance m, frame of `earlier`, frame of `later`, angle deg) of the closest pair of views,
    or None when no pair is within max_angle."""
    first = np.arange(earlier["first_frame"], earlier["last_frame"] + 1)
    second = np.arange(later["first_frame"], later["last_frame"] + 1)
    seam = later["first_frame"]
    first = first[first < seam - seam_frames]
    second = second[second > seam + seam_frames]
    best = None
    cos_limit = np.cos(np.radians(max_angle))
    for frame in second:
        cosines = axes[first] @ axes[frame]
        near = np.where(cosines >= cos_limit)[0]
        if near.size == 0:
            continue
        distances = np.linalg.norm(positions[first[near]] - positions[frame], axis=1)
        k = int(np.argmin(distances))
        if best is None or distances[k] < best[0]:
            angle = float(np.degrees(np.arccos(min(1.0, cosines[near[k]]))))
            best = (float(distances[k]), int(first[near[k]]), int(frame), angle)
    return best


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--run", required=True, type=Path, help="the run's output folder")
    parser.add_argument("--sequence", required=True, type=Path, help="the sequence folder")
    parser.add_argument("--seam-frames", type=int, default=30,
                        help="frames left out on each side of a seam (default 30)")
    parser.add_argument("--max-angle", type=float, default=20.0,
                        help="largest angle between optical axes of one place (default 20)")
    arguments = parser.parse_args(argv)
    try:
        maps = sorted(read_maps(arguments.run / "stats.json"), key=lambda m: m["first_frame"])
        positions, axes = read_ground_truth(arguments.sequence / "groundtruth.txt")
        if maps and maps[-1]["last_frame"] >= len(positions):
            raise InputError(f"{arguments.sequence / 'groundtruth.txt'}: {len(positions)} poses, "
                             f"but the run tracked frame {maps[-1]['last_frame']}")
    except InputError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    if len(maps) < 2:
        print("one map: nothing to merge")
        return 0
    for i, earlier in enumerate(maps):
        for later in maps[i + 1:]:
            found = closest_revisit(positions, axes, earlier, later, arguments.seam_frames,
                                    arguments.max_angle)
            pair = f"map {earlier['id']} (frames {earlier['first_frame']}-{earlier['last_frame']})" \
                   f" and map {later['id']} (frames {later['first_frame']}-{later['last_frame']})"
            if found is None:
                print(f"{pair}: no common view within {arguments.max_angle:g} degrees away from "
                      f"the seam")
            else:
                distance, a, b, angle = found
                print(f"{pair}: closest common view {distance:.3f} m apart, frames {a} and {b}, "
                      f"{angle:.1f} degrees")
    return 0


if __name__ == "__main__":
    sys.exit(main())
