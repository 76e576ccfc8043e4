#!/usr/bin/python3
"""The people a run tracked, seen from above: each track's path (coloured, its id at the end)
over the run's static map and the camera's path.

  tools/people/people_tracks.py RUN [--map RUN/map.ply] [--out tracks.png] [--min-rows 10]

Reads RUN/people.csv and RUN/trajectory.txt, and the map's points when the run wrote them with
`--export-map RUN/map.ply`. "Above" is the opposite of the cameras' mean image-down axis (a hand-
held camera is held about upright). Prints the number of tracks and rows. Exit 2 with the file
named on bad input."""
import argparse
import sys
from pathlib import Path

import numpy as np


class InputError(Exception):
    """Bad or missing input; the message names the file."""


def read_people(path):
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except (OSError, ValueError) as error:
        raise InputError(f"{path}: {error}") from error
    return data  # frame,timestamp,id,x,y,z,vx,vy,vz,extent,visible_pixels


def read_trajectory(path):
    try:
        data = np.loadtxt(path, comments="#", ndmin=2)
    except (OSError, ValueError) as error:
        raise InputError(f"{path}: {error}") from error
    return data[:, 1:4], data[:, 4:8]


def read_ply(path):
    with open(path, "rb") as file:
        count = 0
        while True:
            line = file.readline().decode("ascii", "replace").strip()
            if line.startswith("element vertex"):
                count = int(line.split()[2])
            if line == "end_header" or not line:
                break
        record = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "u1", 3)])
        points = np.frombuffer(file.read(count * record.itemsize), dtype=record)
    return np.stack([points["x"], points["y"], points["z"]], axis=1)


def floor_axes(quaternions):
    """Two unit axes spanning the floor plane: image-down of a TUM quaternion is its R[:, 1]."""
    x, y, z, w = quaternions.T
    down = np.stack([2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)], axis=1)
    up = -down.mean(axis=0)
    up /= np.linalg.norm(up)
    forward = np.array([0.0, 0.0, 1.0]) - up[2] * up
    forward /= np.linalg.norm(forward)
    return np.cross(up, forward), forward


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run", type=Path)
    parser.add_argument("--map", type=Path)
    parser.add_argument("--out", type=Path, default=Path("people_tracks.png"))
    parser.add_argument("--min-rows", type=int, default=10,
                        help="tracks with fewer rows are drawn thin and not labelled")
    parser.add_argument("--title", default="")
    args = parser.parse_args()
    try:
        people = read_people(args.run / "people.csv")
        positions, quaternions = read_trajectory(args.run / "trajectory.txt")
        cloud = read_ply(args.map) if args.map else None
    except InputError as error:
        print(f"people_tracks.py: {error}", file=sys.stderr)
        return 2
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib import pyplot
    right, forward = floor_axes(quaternions)
    flat = lambda points: (points @ right, points @ forward)  # noqa: E731
    figure, axes = pyplot.subplots(figsize=(7, 6))
    if cloud is not None and len(cloud):
        axes.scatter(*flat(cloud), s=0.3, c="0.75", label="static map")
    axes.plot(*flat(positions), c="k", lw=1.2, label="camera")
    ids = np.unique(people[:, 2]).astype(int) if len(people) else []
    colours = pyplot.get_cmap("tab20")
    long_tracks = 0
    for index, track in enumerate(ids):
        rows = people[people[:, 2] == track]
        u, v = flat(rows[:, 3:6])
        long = len(rows) >= args.min_rows
        long_tracks += long
        axes.plot(u, v, c=colours(index % 20), lw=2.0 if long else 0.6)
        if long:
            axes.scatter(u[-1:], v[-1:], c=[colours(index % 20)], s=25)
            axes.annotate(str(track), (u[-1], v[-1]), fontsize=8, xytext=(3, 3),
                          textcoords="offset points")
    axes.set_aspect("equal")
    axes.set_xlabel("m")
    axes.set_ylabel("m")
    axes.set_title(args.title or f"{args.run.name}: {len(ids)} tracks, {len(people)} rows",
                   fontsize=10)
    axes.legend(fontsize=8, loc="best")
    axes.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(args.out, dpi=110)
    print(f"{len(ids)} tracks ({long_tracks} with >= {args.min_rows} rows), {len(people)} rows: "
          f"{args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
