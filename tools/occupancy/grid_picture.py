#!/usr/bin/env python3
"""A picture of a run's 2D occupancy grid (`pspslam run --export-grid GRID.yaml`): the map_server
grid (black occupied, white free, grey unknown) and the keyframe path projected on the floor in
blue.

    tools/occupancy/grid_picture.py RUN_DIR/grid.yaml RUN_DIR/stats.json RUN_DIR/keyframes.txt OUT.png
"""
import json
import sys
from pathlib import Path

import numpy
from PIL import Image, ImageDraw


def read_pgm(path):
    data = path.read_bytes()
    fields, position = [], 0
    while len(fields) < 4:
        while data[position:position + 1].isspace():
            position += 1
        if data[position:position + 1] == b"#":
            position = data.index(b"\n", position) + 1
            continue
        end = position
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[position:end])
        position = end
    width, height = int(fields[1]), int(fields[2])
    raster = data[position + 1:position + 1 + width * height]
    return numpy.frombuffer(raster, dtype=numpy.uint8).reshape(height, width)


def read_yaml(path):
    values = {}
    for line in path.read_text().splitlines():
        if ":" in line and not line.startswith("#"):
            key, value = line.split(":", 1)
            values[key.strip()] = value.strip()
    return values


def main(grid_yaml, stats_json, keyframes_txt, out_png, scale=4):
    grid_yaml = Path(grid_yaml)
    meta = read_yaml(grid_yaml)
    image = read_pgm(grid_yaml.parent / meta["image"])
    resolution = float(meta["resolution"])
    origin = [float(v) for v in meta["origin"].strip("[]").split(",")]
    stats = json.loads(Path(stats_json).read_text())
    T_world_grid = numpy.array(stats["occupancy"]["grid"]["T_world_grid"]).reshape(4, 4)
    T_grid_world = numpy.linalg.inv(T_world_grid)
    picture = Image.fromarray(image).convert("RGB")
    picture = picture.resize((image.shape[1] * scale, image.shape[0] * scale), Image.NEAREST)
    draw = ImageDraw.Draw(picture)
    path = []
    for line in Path(keyframes_txt).read_text().splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        values = [float(v) for v in line.split()]
        g = T_grid_world @ numpy.array([values[1], values[2], values[3], 1.0])
        column = (g[0] - origin[0]) / resolution
        row = image.shape[0] - (g[1] - origin[1]) / resolution
        path.append((column * scale, row * scale))
    if len(path) > 1:
        draw.line(path, fill=(40, 90, 230), width=2)
    picture.save(out_png)


if __name__ == "__main__":
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    main(*sys.argv[1:])
