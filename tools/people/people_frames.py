#!/usr/bin/python3
"""Frames of a run with each tracked person's id drawn where her centre projects, for reading
the tracks by eye against the video: a grid of the chosen frames, four to a row.

  tools/people/people_frames.py RUN SEQUENCE --config CONFIG --frames 220,250,280 --out grid.jpg

Reads RUN/people.csv and RUN/trajectory.txt, SEQUENCE/rgb.txt and its images (TUM layout; a
frame's number is its line in rgb.txt, as people.csv counts them) and the camera's fx, fy, cx, cy
from CONFIG. Needs numpy and Pillow. Exit 2 with the file named on bad input."""
import argparse
import re
import sys
from pathlib import Path

import numpy as np


def rotation(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def intrinsics(config):
    text = config.read_text()
    values = {}
    for key in ("fx", "fy", "cx", "cy"):
        match = re.search(rf"^\s*{key}:\s*([-+0-9.eE]+)", text, re.MULTILINE)
        if not match:
            raise ValueError(f"{config}: no camera key {key}")
        values[key] = float(match.group(1))
    return values


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run", type=Path)
    parser.add_argument("sequence", type=Path)
    parser.add_argument("--config", type=Path, required=True)
    parser.add_argument("--frames", required=True, help="comma-separated frame numbers")
    parser.add_argument("--out", type=Path, default=Path("people_frames.jpg"))
    args = parser.parse_args()
    from PIL import Image, ImageDraw
    try:
        k = intrinsics(args.config)
        rows = np.loadtxt(args.run / "people.csv", delimiter=",", skiprows=1, ndmin=2)
        poses = {round(r[0] * 1e6): r for r in np.loadtxt(args.run / "trajectory.txt", ndmin=2)}
        images = [line.split() for line in (args.sequence / "rgb.txt").read_text().splitlines()
                  if line.strip() and not line.startswith("#")]
        frames = [int(f) for f in args.frames.split(",")]
    except (OSError, ValueError) as error:
        print(f"people_frames.py: {error}", file=sys.stderr)
        return 2
    tiles = []
    for frame in frames:
        stamp, name = float(images[frame][0]), images[frame][1]
        image = Image.open(args.sequence / name).convert("RGB")
        draw = ImageDraw.Draw(image)
        pose = poses.get(round(stamp * 1e6))
        for row in rows[rows[:, 0] == frame] if pose is not None else []:
            centre = rotation(pose[4:8]).T @ (row[3:6] - pose[1:4])
            u = k["fx"] * centre[0] / centre[2] + k["cx"]
            v = k["fy"] * centre[1] / centre[2] + k["cy"]
            draw.ellipse([u - 6, v - 6, u + 6, v + 6], outline=(255, 0, 0), width=3)
            draw.text((u + 8, v - 8), f"{int(row[2])} ({centre[2]:.1f} m)", fill=(255, 255, 0))
        draw.text((5, 5), f"frame {frame}", fill=(255, 255, 255))
        tiles.append(image.resize((320, 240)))
    grid = Image.new("RGB", (320 * min(4, len(tiles)), 240 * ((len(tiles) + 3) // 4)))
    for index, tile in enumerate(tiles):
        grid.paste(tile, ((index % 4) * 320, (index // 4) * 240))
    grid.save(args.out, quality=80)
    print(f"{len(tiles)} frames: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
