#!/usr/bin/python3
"""Per-keyframe diagnosis of local bundle adjustment: which keyframes did BA leave further from
the ground truth than tracking had them, and what do their observations have in common?

usage: tools/diagnosis/ba_keyframes.py --run RUN --sequence SEQ [--masks DIR] [--csv OUT.csv]
       [--markdown OUT.md]

RUN is the output folder of
    pspslam run --sequence SEQ --out RUN --save-map RUN/map.pspmap [--save-masks RUN/masks]
(trajectory.txt: the online poses; keyframes.txt: the keyframes' poses after BA at the end of the
run; map.pspmap: the final map with every keyframe's keypoints and their map points).

Errors: the keyframes after BA and the online poses at the same stamps are each aligned onto the
ground truth (camera pose: groundtruth.txt times body_to_camera.txt when the sequence has one) by
their own least-squares SE(3), over the keyframe stamps, as `pspslam eval` aligns; a keyframe
"moved away" when its position error after BA exceeds the online one.

Features of each keyframe's observations (keypoints with a map point): their count; the shares
far (> 3 m) or without depth, without depth, on a depth edge, on a young point (first seen by this
keyframe or the two before it), on a person (SEQ/mask label != 0, else the run's saved dynamic
mask); the share of its points that later keyframes within 30 frames see on a person; and how
much the person pixel share changes from 10 frames before to 10 frames after.

Writes a CSV per keyframe (--csv) and a markdown summary (--markdown, and stdout): both groups'
medians and means of every feature and each feature's Spearman rank correlation with the error
change (after BA - online, mm). Needs numpy and PIL (Debian python3-numpy, python3-pil).
Exit status 2 with a message naming the file on bad input.
"""
import argparse
import csv
import math
import struct
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

NO_ID = 2**64 - 1
MAX_GT_DIFFERENCE_S = 0.02  # as `pspslam eval --max-dt`
SAME_STAMP_S = 1e-3  # keyframes.txt, trajectory.txt and the map write the same stamps
FAR_DEPTH_M = 3.0
EDGE_WINDOW = 5
EDGE_DEPTH_RANGE_M = 0.1
YOUNG_KEYFRAMES_BEFORE = 2
LATER_KEYFRAME_FRAMES = 30
PERSON_CHANGE_FRAMES = 10
PERMUTATIONS = 2000

FEATURES = [
    "observations", "far_share", "no_depth_share", "edge_share", "young_share", "person_share",
    "person_later_share", "person_later_surface_share", "person_change",
]


class InputError(Exception):
    """Bad or missing input; the message names the file."""


# ---------------------------------------------------------------------------------------------
# Map file (src/pspslam/persistence/map_file.cpp, versions 1 and 2)

MAP_MAGIC = b"PSPSLMAP"
MAP_VERSIONS = (1, 2)
MAP_HEADER = struct.Struct("<8sIIQQ")
MAP_CAMERA = struct.Struct("<5d3Id")
MAP_COUNTS = struct.Struct("<QQ")
MAP_POINT = np.dtype([("id", "<u8"), ("position", "<f8", (3,)), ("reference_keyframe", "<u8"),
                      ("first_keyframe", "<u8")])
MAP_KEYFRAME_HEAD = {1: struct.Struct("<QQd12dQI"),  # ... parent, keypoints
                     2: struct.Struct("<QQd12dQIII")}  # ... parent, map id, anchor, keypoints
MAP_KEYPOINT = np.dtype([("x", "<f4"), ("y", "<f4"), ("size", "<f4"), ("angle", "<f4"),
                         ("response", "<f4"), ("octave", "<i4"), ("depth", "<f4"),
                         ("point", "<u8")])
DESCRIPTOR_BYTES = 32


@dataclass
class MapCamera:
    fx: float
    fy: float
    cx: float
    cy: float
    bf: float
    width: int
    height: int
    pyramid_levels: int
    scale_factor: float


@dataclass
class MapKeyFrame:
    id: int
    frame_id: int
    timestamp: float
    T_camera_world: np.ndarray  # 4x4
    parent: int
    keypoints: np.ndarray  # MAP_KEYPOINT records
    map_id: int = 0  # the map of the atlas (version 1: one map)


@dataclass
class SavedMap:
    camera: MapCamera
    points: np.ndarray  # MAP_POINT records
    keyframes: list  # MapKeyFrame, ascending id


def fnv1a64(data):
    """FNV-1a 64 of bytes, the map file's checksum (about a second per 3 MB)."""
    value = 0xCBF29CE484222325
    for byte in data:
        value = ((value ^ byte) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return value


class PayloadReader:
    """Bounds-checked reading of the payload; failures name the file, offset and field."""

    def __init__(self, payload, path):
        self.payload, self.path, self.offset = payload, path, 0

    def take(self, size, what):
        left = len(self.payload) - self.offset
        if size > left:
            raise InputError(f"{self.path}: truncated map payload: {what} needs {size} bytes at "
                             f"payload byte {self.offset}, only {left} left")
        chunk = self.payload[self.offset:self.offset + size]
        self.offset += size
        return chunk

    def unpack(self, layout, what):
        return layout.unpack(self.take(layout.size, what))

    def records(self, dtype, count, what):
        return np.frombuffer(self.take(dtype.itemsize * count, what), dtype=dtype, count=count)


def checked_map_payload(data, path):
    if data[:len(MAP_MAGIC)] != MAP_MAGIC[:len(data)]:
        raise InputError(f"{path}: not a pspslam map (bad magic, expected \"PSPSLMAP\")")
    if len(data) < MAP_HEADER.size:
        raise InputError(f"{path}: truncated map file (the header needs {MAP_HEADER.size} bytes, "
                         f"the file has {len(data)})")
    _, version, _, payload_bytes, checksum = MAP_HEADER.unpack_from(data)
    if version not in MAP_VERSIONS:
        raise InputError(f"{path}: unsupported map format version {version} (this tool reads "
                         f"versions {MAP_VERSIONS[0]} to {MAP_VERSIONS[-1]})")
    payload = data[MAP_HEADER.size:]
    if len(payload) < payload_bytes:
        raise InputError(f"{path}: truncated map file (header announces {payload_bytes} payload "
                         f"bytes, the file has {len(payload)})")
    if len(payload) > payload_bytes:
        raise InputError(f"{path}: {len(payload) - payload_bytes} unexpected bytes after the "
                         f"map payload")
    if fnv1a64(payload) != checksum:
        raise InputError(f"{path}: map checksum mismatch: the file is corrupt")
    return payload, version


def read_map(path):
    """The saved map: camera, points and keyframes (descriptors skipped)."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as error:
        raise InputError(f"{path}: cannot read map file ({error.strerror}); write it with "
                         f"`pspslam run ... --save-map {path}`") from None
    payload, version = checked_map_payload(data, path)
    reader = PayloadReader(payload, path)
    camera = MapCamera(*reader.unpack(MAP_CAMERA, "camera"))
    keyframe_count, point_count = reader.unpack(MAP_COUNTS, "counts")
    if point_count * MAP_POINT.itemsize > len(reader.payload):
        raise InputError(f"{path}: inconsistent map: {point_count} map points cannot fit in "
                         f"{len(reader.payload)} payload bytes")
    points = reader.records(MAP_POINT, point_count, "map points")
    keyframes = []
    for index in range(keyframe_count):
        what = f"keyframe {index} of {keyframe_count}"
        head = reader.unpack(MAP_KEYFRAME_HEAD[version], what)
        keyframe_id, frame_id, timestamp = head[0], head[1], head[2]
        pose = np.eye(4)
        pose[:3, :3] = np.array(head[3:12]).reshape(3, 3)
        pose[:3, 3] = head[12:15]
        parent, keypoint_count = head[15], head[-1]
        map_id = head[16] if version >= 2 else 0
        keypoints = reader.records(MAP_KEYPOINT, keypoint_count, f"{what} keypoints")
        reader.take(keypoint_count * DESCRIPTOR_BYTES, f"{what} descriptors")
        keyframes.append(MapKeyFrame(keyframe_id, frame_id, timestamp, pose, parent, keypoints,
                                     map_id))
    if reader.offset != len(reader.payload):
        raise InputError(f"{path}: {len(reader.payload) - reader.offset} map payload bytes left "
                         f"after the last keyframe")
    keyframes.sort(key=lambda keyframe: keyframe.id)
    return SavedMap(camera, points, keyframes)


# ---------------------------------------------------------------------------------------------
# Text files of the run and the sequence


def data_lines(path, what):
    """(line number, fields) of every non-comment line of a text file."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: missing {what}")
    with open(path) as stream:
        for number, line in enumerate(stream, 1):
            fields = line.split()
            if fields and not fields[0].startswith("#"):
                yield number, fields


def parse_numbers(path, number, fields):
    try:
        return [float(value) for value in fields]
    except ValueError:
        raise InputError(f"{path}:{number}: expected numbers, got '{' '.join(fields)}'") from None


@dataclass
class Trajectory:
    stamps: np.ndarray  # (n,)
    positions: np.ndarray  # (n, 3) camera centres in the world
    rotations: np.ndarray  # (n, 3, 3) camera-to-world


def read_tum_trajectory(path, what):
    rows = []
    for number, fields in data_lines(path, what):
        if len(fields) != 8:
            raise InputError(f"{path}:{number}: expected 'timestamp tx ty tz qx qy qz qw', got "
                             f"{len(fields)} fields")
        rows.append(parse_numbers(path, number, fields))
    if not rows:
        raise InputError(f"{path}: {what} has no pose")
    rows = np.array(rows)
    return Trajectory(rows[:, 0], rows[:, 1:4], quaternions_to_matrices(rows[:, 4:8]))


def quaternions_to_matrices(quaternions):
    """Rotation matrices of (qx, qy, qz, qw) rows."""
    q = quaternions / np.linalg.norm(quaternions, axis=1, keepdims=True)
    x, y, z, w = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def read_rigid_transform(path):
    """T_body_camera as `pspslam eval --gt-body-to-camera` reads it: 'tx ty tz qx qy qz qw' on one
    line, or a 3x4 / 4x4 matrix."""
    rows = [parse_numbers(path, number, fields) for number, fields in
            data_lines(path, "body-to-camera transform")]
    transform = np.eye(4)
    if len(rows) == 1 and len(rows[0]) == 7:
        transform[:3, :3] = quaternions_to_matrices(np.array([rows[0][3:7]]))[0]
        transform[:3, 3] = rows[0][:3]
    elif len(rows) in (3, 4) and all(len(row) == 4 for row in rows):
        transform[:len(rows)] = rows
        u, _, vt = np.linalg.svd(transform[:3, :3])  # 4-digit matrices are rotations up to rounding
        transform[:3, :3] = u @ vt
    else:
        raise InputError(f"{path}: expected 'tx ty tz qx qy qz qw' on one line or a 4x4 matrix")
    return transform


def read_ground_truth_cameras(sequence):
    """Ground-truth camera poses: the marker body moved onto the camera when the sequence has
    body_to_camera.txt (camera pose = T_world_body * T_body_camera, as `pspslam eval` does)."""
    truth = read_tum_trajectory(sequence / "groundtruth.txt", "ground-truth trajectory")
    body_to_camera = sequence / "body_to_camera.txt"
    if body_to_camera.is_file():
        T_body_camera = read_rigid_transform(body_to_camera)
        truth.positions = truth.positions + truth.rotations @ T_body_camera[:3, 3]
        truth.rotations = truth.rotations @ T_body_camera[:3, :3]
    return truth


def read_file_list(path, what):
    entries = []
    for number, fields in data_lines(path, what):
        if len(fields) < 2:
            raise InputError(f"{path}:{number}: expected 'timestamp file'")
        entries.append((parse_numbers(path, number, fields[:1])[0], fields[1]))
    return entries


@dataclass
class SequenceFrame:
    stamp: float
    colour_file: str  # relative to the sequence
    depth_file: str  # relative to the sequence; None without an associated depth image


def read_sequence_frames(sequence):
    """The sequence's frames in time order, as the run reads them: associations.txt when it exists,
    else rgb.txt with depth.txt associated within 20 ms."""
    associations = sequence / "associations.txt"
    if associations.is_file():
        frames = []
        for number, fields in data_lines(associations, "association file"):
            if len(fields) != 4:
                raise InputError(f"{associations}:{number}: expected 't_rgb rgb_file t_depth "
                                 f"depth_file'")
            frames.append(SequenceFrame(parse_numbers(associations, number, fields[:1])[0],
                                        fields[1], fields[3]))
    else:
        colour = read_file_list(sequence / "rgb.txt", "colour image list (rgb.txt)")
        depth = read_file_list(sequence / "depth.txt", "depth image list (depth.txt)")
        # The run skips listed files that are missing; the nearest present one stands in.
        depth = [(stamp, name) for stamp, name in depth if (sequence / name).is_file()]
        pairs = associate([stamp for stamp, _ in colour], [stamp for stamp, _ in depth],
                          MAX_GT_DIFFERENCE_S)
        depth_of = dict(pairs)
        frames = [SequenceFrame(stamp, name, depth[depth_of[i]][1] if i in depth_of else None)
                  for i, (stamp, name) in enumerate(colour)]
    if not frames:
        raise InputError(f"{sequence}: the sequence lists no frame")
    return sorted(frames, key=lambda frame: frame.stamp)


def associate(first, second, max_difference):
    """Unique (i, j) pairs of stamps closer than max_difference, the closest first (TUM's
    associate.py, as the project's ATE associates)."""
    first, second = np.asarray(first, float), np.asarray(second, float)
    order = np.argsort(second)
    candidates = []
    for i, stamp in enumerate(first):
        low = np.searchsorted(second[order], stamp - max_difference, "left")
        high = np.searchsorted(second[order], stamp + max_difference, "right")
        for j in order[low:high]:
            difference = abs(stamp - second[j])
            if difference < max_difference:
                candidates.append((difference, stamp, second[j], i, j))
    used_first, used_second, pairs = set(), set(), []
    for _, _, _, i, j in sorted(candidates):
        if i not in used_first and j not in used_second:
            used_first.add(i)
            used_second.add(j)
            pairs.append((i, j))
    return sorted(pairs)


def read_camera_config(run, sequence):
    """Depth factor, lens distortion and depth registration shift from the config the run used
    (RUN/run_config.yaml), else SEQ/config.yaml, else defaults. Reads only the `camera:` block's
    `key: value` lines, which is all these files hold there."""
    values = {"depth_factor": 5000.0, "distortion": [0.0] * 5,
              "depth_registration_shift_px": [0.0, 0.0]}
    for path in (run / "run_config.yaml", sequence / "config.yaml"):
        if path.is_file():
            values.update(camera_block(path))
            values["source"] = str(path)
            break
    distortion = list(values["distortion"]) + [0.0] * 5
    values["distortion"] = [float(k) for k in distortion[:5]]
    return values


def camera_block(path):
    block, inside = {}, False
    for line in path.read_text().splitlines():
        text = line.split("#", 1)[0].rstrip()
        if not text:
            continue
        if not text.startswith(" "):
            inside = text.strip() == "camera:"
            continue
        if inside and ":" in text:
            key, value = (part.strip() for part in text.split(":", 1))
            try:
                if value.startswith("["):
                    block[key] = [float(item) for item in value.strip("[]").split(",") if item]
                elif value:
                    block[key] = float(value)
            except ValueError:
                continue  # names and other text: not needed here
    return block


# ---------------------------------------------------------------------------------------------
# Images


def read_png(path):
    """A PNG as a numpy array (16-bit depth keeps its values), or None when the file is missing."""
    from PIL import Image  # imported here so that --help works without PIL
    if not path.is_file():
        return None
    try:
        with Image.open(path) as image:
            pixels = np.array(image)
    except OSError as error:
        raise InputError(f"{path}: cannot read image ({error})") from None
    return pixels[..., 0] if pixels.ndim == 3 else pixels


class FrameImages:
    """Depth (metres) and person masks of the sequence's frames, read once each."""

    def __init__(self, sequence, frames, config, saved_masks):
        self.sequence, self.frames, self.config = sequence, frames, config
        self.label_folder = sequence / "mask"
        if self.label_folder.is_dir():
            self.mask_folder, self.mask_source = self.label_folder, f"{self.label_folder} " \
                "(ground-truth labels; != 0: person or carried object)"
        elif saved_masks is not None:
            self.mask_folder, self.mask_source = saved_masks, f"{saved_masks} (the run's saved " \
                "dynamic masks, semantic + geometry; != 0: dynamic)"
        else:
            self.mask_folder, self.mask_source = None, "none (person features left empty)"
        self.depth_cache, self.mask_cache = {}, {}

    def depth(self, index):
        if index not in self.depth_cache:
            name = self.frames[index].depth_file
            raw = None if name is None else read_png(self.sequence / name)
            self.depth_cache[index] = None if raw is None else \
                raw.astype(np.float32) / self.config["depth_factor"]
        return self.depth_cache[index]

    def person(self, index):
        """Boolean person mask of frame `index` (named after the colour image), None if none."""
        if self.mask_folder is None or not 0 <= index < len(self.frames):
            return None
        if index not in self.mask_cache:
            stem = Path(self.frames[index].colour_file).stem
            mask = read_png(self.mask_folder / f"{stem}.png")
            self.mask_cache[index] = None if mask is None else mask != 0
        return self.mask_cache[index]


class PixelLookup:
    """Image pixels of undistorted pixel coordinates. The keypoints and projections are
    undistorted; the images are not, so the config's lens distortion (OpenCV k1 k2 p1 p2 k3) is
    applied before taking the nearest pixel."""

    def __init__(self, camera, config):
        self.camera = camera
        self.k1, self.k2, self.p1, self.p2, self.k3 = config["distortion"]
        self.depth_shift = [int(round(s)) for s in config["depth_registration_shift_px"]]

    def distorted(self, u, v):
        c = self.camera
        x, y = (u - c.cx) / c.fx, (v - c.cy) / c.fy
        r2 = x * x + y * y
        radial = 1 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3))
        xd = x * radial + 2 * self.p1 * x * y + self.p2 * (r2 + 2 * x * x)
        yd = y * radial + self.p1 * (r2 + 2 * y * y) + 2 * self.p2 * x * y
        return c.fx * xd + c.cx, c.fy * yd + c.cy

    def pixels(self, u, v):
        """(columns, rows, inside) of the nearest image pixels."""
        ud, vd = self.distorted(np.asarray(u, float), np.asarray(v, float))
        columns, rows = np.rint(ud).astype(int), np.rint(vd).astype(int)
        inside = (columns >= 0) & (columns < self.camera.width) & (rows >= 0) & \
            (rows < self.camera.height)
        return np.clip(columns, 0, self.camera.width - 1), \
            np.clip(rows, 0, self.camera.height - 1), inside

    def depth_windows(self, depth, columns, rows):
        """(n, 25) depth of the 5x5 windows around the pixels (the depth image read where the
        config's depth_registration_shift_px puts the colour pixel; borders clamped)."""
        half = EDGE_WINDOW // 2
        offsets = np.arange(-half, half + 1)
        window_rows = np.clip(rows[:, None, None] + self.depth_shift[1] + offsets[None, :, None],
                              0, depth.shape[0] - 1)
        window_columns = np.clip(columns[:, None, None] + self.depth_shift[0] +
                                 offsets[None, None, :], 0, depth.shape[1] - 1)
        return depth[window_rows, window_columns].reshape(len(rows), -1)


# ---------------------------------------------------------------------------------------------
# Errors of the keyframes after BA and online


def align_rigid(estimate, truth):
    """R, t minimising sum |R estimate + t - truth|^2 (Horn / Umeyama without scale)."""
    estimate_mean, truth_mean = estimate.mean(0), truth.mean(0)
    u, _, vt = np.linalg.svd((truth - truth_mean).T @ (estimate - estimate_mean))
    signs = np.diag([1.0, 1.0, np.sign(np.linalg.det(u) * np.linalg.det(vt)) or 1.0])
    rotation = u @ signs @ vt
    return rotation, truth_mean - rotation @ estimate_mean


def aligned_errors(positions, truth_positions):
    """Position errors (m) after aligning `positions` onto the truth; NaN rows are left out of the
    alignment and stay NaN."""
    errors = np.full(len(positions), np.nan)
    usable = ~np.isnan(positions).any(1) & ~np.isnan(truth_positions).any(1)
    if usable.sum() < 3:
        return errors
    rotation, translation = align_rigid(positions[usable], truth_positions[usable])
    aligned = positions[usable] @ rotation.T + translation
    errors[usable] = np.linalg.norm(aligned - truth_positions[usable], axis=1)
    return errors


def nearest_indices(stamps, queries, tolerance):
    """Index into `stamps` of the one nearest each query within tolerance, else -1."""
    stamps = np.asarray(stamps, float)
    order = np.argsort(stamps)
    sorted_stamps = stamps[order]
    indices = np.full(len(queries), -1)
    for k, query in enumerate(queries):
        at = np.searchsorted(sorted_stamps, query)
        near = [i for i in (at - 1, at) if 0 <= i < len(sorted_stamps)]
        best = min(near, key=lambda i: abs(sorted_stamps[i] - query))
        if abs(sorted_stamps[best] - query) <= tolerance:
            indices[k] = order[best]
    return indices


def positions_at(trajectory, indices):
    positions = np.full((len(indices), 3), np.nan)
    found = indices >= 0
    positions[found] = trajectory.positions[indices[found]]
    return positions


# ---------------------------------------------------------------------------------------------
# Features of the observations


def share(flags):
    return float(np.mean(flags)) if len(flags) else math.nan


def on_depth_edge(depth_windows):
    """A depth edge: the valid depth of the window spans > 0.1 m, or holes lie next to valid
    depth. A window without any depth is a hole, not an edge (no_depth_share counts those)."""
    valid = depth_windows > 0
    with np.errstate(invalid="ignore"):
        low = np.where(valid, depth_windows, np.inf).min(1)
        high = np.where(valid, depth_windows, -np.inf).max(1)
    some_valid = valid.any(1)
    return some_valid & (~valid.all(1) | (high - low > EDGE_DEPTH_RANGE_M))


def project(T_camera_world, positions, camera):
    """(u, v, z) of world points in an undistorted pinhole camera."""
    in_camera = positions @ T_camera_world[:3, :3].T + T_camera_world[:3, 3]
    z = in_camera[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = camera.fx * in_camera[:, 0] / z + camera.cx
        v = camera.fy * in_camera[:, 1] / z + camera.cy
    return u, v, z


def later_person_hits(positions, later_keyframes, camera, lookup, images):
    """Per point: seen on a person by any later keyframe (in the image, in front of it), and seen
    on a person whose depth there agrees with the point's (the point lies on the person, not
    behind one passing in front). None when no later keyframe has a mask."""
    on_person = np.zeros(len(positions), bool)
    on_person_surface = np.zeros(len(positions), bool)
    any_mask = False
    for keyframe, frame_index in later_keyframes:
        mask = images.person(frame_index)
        if mask is None:
            continue
        any_mask = True
        u, v, z = project(keyframe.T_camera_world, positions, camera)
        visible = (z > 0) & (u >= 0) & (u <= camera.width - 1) & (v >= 0) & \
            (v <= camera.height - 1)
        columns, rows, inside = lookup.pixels(np.where(visible, u, 0), np.where(visible, v, 0))
        hit = visible & inside & mask[rows, columns]
        on_person |= hit
        depth = images.depth(frame_index)
        if depth is not None:
            centre = lookup.depth_windows(depth, columns, rows)[:, EDGE_WINDOW ** 2 // 2]
            # Kinect depth noise grows with z^2; 0.1 m + 5 % holds the readings at 4 m.
            agrees = (centre > 0) & (np.abs(centre - z) < 0.1 + 0.05 * np.abs(z))
            on_person_surface |= hit & agrees
    return (on_person, on_person_surface) if any_mask else None


def person_pixel_share(images, index):
    index = min(max(index, 0), len(images.frames) - 1)  # frames that exist
    mask = images.person(index)
    return math.nan if mask is None else float(mask.mean())


@dataclass
class KeyFrameContext:
    keyframe: MapKeyFrame
    frame_index: int  # in the sequence's frame list, -1 when the stamp is not there
    rank: int  # position in the map's keyframes by id
    features: dict = field(default_factory=dict)


def keyframe_features(context, contexts, saved_map, points_by_id, lookup, images):
    keyframe = context.keyframe
    keypoints = keyframe.keypoints
    # A keypoint without a map point, or on one the map did not save, is no observation.
    observed = np.array([point != NO_ID and point in points_by_id
                         for point in keypoints["point"]], bool)
    keypoints = keypoints[observed]
    rows = np.array([points_by_id[point] for point in keypoints["point"]], int)
    points = saved_map.points[rows] if len(rows) else saved_map.points[:0]
    depth = keypoints["depth"].astype(float)
    no_depth = ~(depth > 0)
    features = {"observations": len(keypoints), "no_depth_share": share(no_depth),
                "far_share": share(no_depth | (depth > FAR_DEPTH_M))}

    # Young: first seen by this keyframe or one of the two before it in id order (keyframes
    # culled since lie in between by id and count as young too).
    oldest_young = contexts[max(context.rank - YOUNG_KEYFRAMES_BEFORE, 0)].keyframe.id
    first = points["first_keyframe"]
    features["young_share"] = share((first >= oldest_young) & (first <= keyframe.id))

    columns, rows_px, inside = lookup.pixels(keypoints["x"], keypoints["y"])
    frame_depth = images.depth(context.frame_index) if context.frame_index >= 0 else None
    features["edge_share"] = math.nan if frame_depth is None else share(
        on_depth_edge(lookup.depth_windows(frame_depth, columns, rows_px)))
    mask = images.person(context.frame_index) if context.frame_index >= 0 else None
    features["person_share"] = math.nan if mask is None else share(
        inside & mask[rows_px, columns])

    later = [(other.keyframe, other.frame_index) for other in contexts[context.rank + 1:]
             if 0 < other.frame_index - context.frame_index <= LATER_KEYFRAME_FRAMES]
    hits = later_person_hits(points["position"], later, saved_map.camera, lookup, images) \
        if later and context.frame_index >= 0 else None
    features["person_later_share"] = math.nan if hits is None else share(hits[0])
    features["person_later_surface_share"] = math.nan if hits is None else share(hits[1])

    if context.frame_index >= 0:
        before = person_pixel_share(images, context.frame_index - PERSON_CHANGE_FRAMES)
        after = person_pixel_share(images, context.frame_index + PERSON_CHANGE_FRAMES)
        features["person_change"] = abs(after - before)
    else:
        features["person_change"] = math.nan
    return features


# ---------------------------------------------------------------------------------------------
# Statistics and output


def ranks(values):
    """Ranks 1..n, ties sharing their mean rank."""
    order = np.argsort(values, kind="mergesort")
    sorted_values = values[order]
    result = np.empty(len(values))
    start = 0
    while start < len(values):
        end = start
        while end + 1 < len(values) and sorted_values[end + 1] == sorted_values[start]:
            end += 1
        result[order[start:end + 1]] = (start + end) / 2 + 1
        start = end + 1
    return result


def spearman(x, y, permutations=PERMUTATIONS):
    """(rho, two-sided permutation p, n) over the pairs where both are numbers."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    usable = ~np.isnan(x) & ~np.isnan(y)
    n = int(usable.sum())
    if n < 3:
        return math.nan, math.nan, n
    rank_x, rank_y = ranks(x[usable]), ranks(y[usable])
    rank_x, rank_y = rank_x - rank_x.mean(), rank_y - rank_y.mean()
    scale = math.sqrt((rank_x ** 2).sum() * (rank_y ** 2).sum())
    if scale == 0:
        return math.nan, math.nan, n
    rho = float(rank_x @ rank_y / scale)
    # Fixed seed: the same run gives the same report.
    shuffled = np.random.default_rng(0).permuted(np.tile(rank_y, (permutations, 1)), axis=1)
    null = shuffled @ rank_x / scale
    p = (1 + np.sum(np.abs(null) >= abs(rho) - 1e-12)) / (permutations + 1)
    return rho, float(p), n


def nan_statistic(function, values):
    values = np.asarray(values, float)
    values = values[~np.isnan(values)]
    return float(function(values)) if len(values) else math.nan


def number(value, digits=3):
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    return f"{value:.{digits}f}"


def markdown_summary(run, sequence, table, rmse, images, notes):
    error_change = np.array([row["error_change_mm"] for row in table], float)
    away = np.array([row["moved_away"] == 1 for row in table])
    closer = np.array([row["moved_away"] == 0 for row in table])
    lines = [
        "# Local BA per keyframe: moved away from the ground truth or closer",
        "",
        f"Run: `{run}`  ",
        f"Sequence: `{sequence}`  ",
        f"Person masks: {images.mask_source}",
        "",
        f"Keyframes: {len(table)}; with an error after BA and online: "
        f"{int(away.sum() + closer.sum())}; **BA moved {int(away.sum())} away, "
        f"{int(closer.sum())} closer**.  ",
        f"Keyframe ATE RMSE, each set SE(3)-aligned on its own: online "
        f"{number(rmse['online'] * 1000, 2)} mm (n = {rmse['online_n']}), after BA "
        f"{number(rmse['after_ba'] * 1000, 2)} mm (n = {rmse['after_ba_n']}).  ",
        f"Error change after BA − online (mm): median "
        f"{number(nan_statistic(np.median, error_change), 1)}, mean "
        f"{number(nan_statistic(np.mean, error_change), 1)}; moved away: median "
        f"{number(nan_statistic(np.median, error_change[away]), 1)}; closer: median "
        f"{number(nan_statistic(np.median, error_change[closer]), 1)}.",
        "",
        "| feature | median away | median closer | mean away | mean closer "
        "| Spearman ρ vs Δerror | p (perm.) | n |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    # The online error itself comes first, as a control: Δerror contains −(online error), so a
    # keyframe tracking had nearly right can hardly get closer; a feature that only follows the
    # online error says nothing about BA.
    columns = [("error_online_mm (control)",
                np.array([row["error_online_m"] for row in table], float) * 1000, 1)]
    columns += [(name, np.array([row[name] for row in table], float),
                 0 if name == "observations" else 3) for name in FEATURES]
    for name, values, digits in columns:
        rho, p, n = spearman(values, error_change)
        lines.append(
            f"| {name} | {number(nan_statistic(np.median, values[away]), digits)} "
            f"| {number(nan_statistic(np.median, values[closer]), digits)} "
            f"| {number(nan_statistic(np.mean, values[away]), digits)} "
            f"| {number(nan_statistic(np.mean, values[closer]), digits)} "
            f"| {number(rho, 2)} | {number(p, 3)} | {n} |")
    lines += ["", "Δerror = position error after BA − online (mm), per keyframe; ρ > 0: more of "
              "the feature goes with BA moving the keyframe away. p: share of "
              f"{PERMUTATIONS} random pairings with |ρ| at least as large. person_later_share "
              "counts a point when a later keyframe sees a person at its pixel, also one passing "
              "in front of it; person_later_surface_share only where that person's depth agrees "
              "with the point's (the point lies on the person)."]
    lines += [f"Note: {note}" for note in notes]
    return "\n".join(lines) + "\n"


CSV_COLUMNS = ["keyframe_id", "frame_id", "frame_index", "timestamp", "error_online_m",
               "error_after_ba_m", "error_change_mm", "moved_away"] + FEATURES


def write_csv(path, table):
    with open(path, "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=CSV_COLUMNS)
        writer.writeheader()
        for row in table:
            writer.writerow({key: ("" if isinstance(value, float) and math.isnan(value) else
                                   (f"{value:.6g}" if isinstance(value, float) else value))
                             for key, value in row.items()})


# ---------------------------------------------------------------------------------------------


def keyframe_errors(after_ba, online, truth):
    """Position errors (m) of the keyframes after BA and of the online poses at their stamps, each
    set aligned on its own; and notes on keyframes left without one."""
    stamps = after_ba.stamps
    truth_at = np.full(len(stamps), -1)
    for i, j in associate(stamps, truth.stamps, MAX_GT_DIFFERENCE_S):
        truth_at[i] = j
    truth_positions = positions_at(truth, truth_at)
    online_positions = positions_at(online, nearest_indices(online.stamps, stamps, SAME_STAMP_S))
    notes = []
    for what, count in (("without ground truth within 20 ms", (truth_at < 0).sum()),
                        ("without an online pose in trajectory.txt",
                         np.isnan(online_positions).any(1).sum())):
        if count:
            notes.append(f"{count} keyframe(s) {what}")
    return (aligned_errors(after_ba.positions, truth_positions),
            aligned_errors(online_positions, truth_positions), notes)


def map_keyframe_features(saved_map, frames, images, lookup):
    """The map's keyframes (ascending id) with the features of their observations."""
    frame_of_keyframe = nearest_indices([frame.stamp for frame in frames],
                                        [keyframe.timestamp for keyframe in saved_map.keyframes],
                                        MAX_GT_DIFFERENCE_S)
    contexts = [KeyFrameContext(keyframe, int(frame_of_keyframe[rank]), rank)
                for rank, keyframe in enumerate(saved_map.keyframes)]
    points_by_id = {int(point_id): row for row, point_id in enumerate(saved_map.points["id"])}
    for context in contexts:
        context.features = keyframe_features(context, contexts, saved_map, points_by_id, lookup,
                                             images)
    return contexts


def diagnose(run, sequence, saved_masks):
    """(one row per line of keyframes.txt, RMSEs, frame images, notes)."""
    after_ba = read_tum_trajectory(run / "keyframes.txt", "keyframe trajectory")
    online = read_tum_trajectory(run / "trajectory.txt", "online trajectory")
    saved_map = read_map(run / "map.pspmap")
    truth = read_ground_truth_cameras(sequence)
    frames = read_sequence_frames(sequence)
    config = read_camera_config(run, sequence)
    images = FrameImages(sequence, frames, config, saved_masks)

    error_after_ba, error_online, notes = keyframe_errors(after_ba, online, truth)
    contexts = map_keyframe_features(saved_map, frames, images,
                                     PixelLookup(saved_map.camera, config))
    map_row = nearest_indices([context.keyframe.timestamp for context in contexts],
                              after_ba.stamps, SAME_STAMP_S)
    if (map_row < 0).any():
        notes.append(f"{(map_row < 0).sum()} keyframe(s) of keyframes.txt not in the map")
    table = []
    for k, stamp in enumerate(after_ba.stamps):
        context = contexts[map_row[k]] if map_row[k] >= 0 else None
        change_mm = (error_after_ba[k] - error_online[k]) * 1000
        table.append({
            "keyframe_id": context.keyframe.id if context else "",
            "frame_id": context.keyframe.frame_id if context else "",
            "frame_index": context.frame_index if context else "",
            "timestamp": f"{stamp:.6f}",
            "error_online_m": error_online[k], "error_after_ba_m": error_after_ba[k],
            "error_change_mm": change_mm,
            "moved_away": "" if math.isnan(change_mm) else int(change_mm > 0),
            **{name: (context.features[name] if context else math.nan) for name in FEATURES},
        })
    rmse = {"after_ba": rms(error_after_ba), "after_ba_n": int((~np.isnan(error_after_ba)).sum()),
            "online": rms(error_online), "online_n": int((~np.isnan(error_online)).sum())}
    return table, rmse, images, notes


def rms(errors):
    errors = errors[~np.isnan(errors)]
    return float(np.sqrt(np.mean(errors ** 2))) if len(errors) else math.nan


def parse_arguments(argv):
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        epilog="Example: tools/diagnosis/ba_keyframes.py --run out/dev --sequence "
               "../shared/data/bonn_crowd_dev --masks out/dev/masks --csv dev.csv",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--run", required=True, type=Path,
                        help="output folder of `pspslam run --save-map RUN/map.pspmap`: "
                             "trajectory.txt, keyframes.txt, map.pspmap")
    parser.add_argument("--sequence", required=True, type=Path,
                        help="the TUM-layout sequence the run read (groundtruth.txt, optional "
                             "body_to_camera.txt, depth, optional mask/ labels)")
    parser.add_argument("--masks", type=Path,
                        help="the run's saved dynamic masks (--save-masks DIR), for sequences "
                             "without mask/ (SEQ/mask is preferred when it exists)")
    parser.add_argument("--csv", type=Path, help="write one row per keyframe here")
    parser.add_argument("--markdown", type=Path, help="write the summary here too")
    return parser.parse_args(argv)


def main(argv=None):
    arguments = parse_arguments(argv)
    try:
        for folder, what in ((arguments.run, "run folder"), (arguments.sequence, "sequence")):
            if not folder.is_dir():
                raise InputError(f"{folder}: no such {what} (not a folder)")
        if arguments.masks is not None and not arguments.masks.is_dir():
            raise InputError(f"{arguments.masks}: no such --masks folder")
        table, rmse, images, notes = diagnose(arguments.run, arguments.sequence, arguments.masks)
        summary = markdown_summary(arguments.run, arguments.sequence, table, rmse, images, notes)
        if arguments.csv:
            write_csv(arguments.csv, table)
        if arguments.markdown:
            arguments.markdown.write_text(summary)
    except InputError as error:
        print(f"ba_keyframes.py: error: {error}", file=sys.stderr)
        return 2
    except ImportError as error:
        print(f"ba_keyframes.py: error: {error} (install python3-pil)", file=sys.stderr)
        return 2
    sys.stdout.write(summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
