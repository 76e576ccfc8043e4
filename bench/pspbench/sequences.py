"""Turning a cell (and a variant's changes to it) into a sequence folder, a config and the
ground truths it is scored on.

Derived sequences (synthetic renderings, slices, re-encodings) are made once under
WORK/sequences/, in folders named by the digest of their recipe, and written to a temporary
folder first: a folder under its final name is complete.
"""
import json
import os
import shutil
import subprocess
import threading
import uuid
from dataclasses import dataclass, field
from pathlib import Path

from . import content
from .experiment import ExperimentError


@dataclass
class Setup:
    """Where things are for this invocation."""
    repo: Path
    build: Path
    cli: Path
    cli_sha256: str
    shared: Path
    data: Path | None
    work: Path
    models_sha256: str | None
    limit_frames: int = 0


@dataclass
class Prepared:
    """A cell ready to run: its folder, identity, config text and evaluation stretches."""
    folder: Path
    identity: str
    config_text: str | None
    stretches: list = field(default_factory=list)  # {"name", "ground_truth", "body_to_camera"}
    max_frames: int = 0


@dataclass
class Missing:
    """A cell whose data is not here: listed as missing in the tables, never left out."""
    reason: str


def prepare(experiment, cell, variant, setup):
    """The cell as `variant` runs it, or Missing; raises ExperimentError for a bad setting."""
    if cell.source == "program":
        program = setup.build / "bench" / cell.location
        if not os.access(program, os.X_OK):
            return Missing(f"{program} is not built")
        return Prepared(program, content.file_sha256(program), None)
    found = _source_folder(cell, variant, setup)
    if isinstance(found, Missing):
        return found
    folder, identity = found
    if experiment.kind == "segment":
        return _image_split(experiment, cell, folder, identity, setup)
    if cell.reencode_jpeg:
        tool = setup.build / "bench" / "reencode_colour"
        if not os.access(tool, os.X_OK):
            return Missing(f"{tool} is not built (cmake --build BUILD --target reencode_colour)")
        folder, identity = _reencoded(folder, identity, cell.reencode_jpeg, tool, setup)
    if cell.start:
        folder, identity = _sliced(folder, identity, cell.start, setup)
    config_text = _config_text(experiment, cell, variant, folder, setup)
    stretches = _stretches(cell, folder, identity, setup)
    return Prepared(folder, identity, config_text, stretches, cell.max_frames)


def _source_folder(cell, variant, setup):
    if cell.source == "synth":
        return _synthetic(cell, variant, setup)
    if cell.source == "shared":
        folder = setup.shared / cell.location
        if not folder.is_dir():
            return Missing(f"{folder} not found (--shared or PSPSLAM_SHARED)")
    else:
        if setup.data is None:
            return Missing(f"{cell.location}: no --data folder given")
        folder = setup.data / cell.location
        if not folder.is_dir():
            return Missing(f"{cell.location} not in {setup.data}")
    return folder, content.folder_identity(folder)


_locks_guard = threading.Lock()
_locks = {}


def _make_once(target, build):
    """Runs build(temporary_folder) unless `target` exists, then renames it into place. Cells
    that share a sequence wait for the one that makes it."""
    with _locks_guard:
        lock = _locks.setdefault(target, threading.Lock())
    with lock:
        if target.is_dir():
            return
        temporary = target.with_name(f".{target.name}.{uuid.uuid4().hex}.tmp")
        build(temporary)
        try:
            temporary.rename(target)
        except OSError:  # made meanwhile by another runner
            shutil.rmtree(temporary, ignore_errors=True)


def _synthetic(cell, variant, setup):
    recipe = {**cell.synth, **variant.synth}
    identity = content.digest({"synth": recipe, "pspslam_sha256": setup.cli_sha256})
    target = setup.work / "sequences" / f"synth-{identity[:16]}"

    def render(folder):
        command = [str(setup.cli), "-q", "synth", "--out", str(folder), "--threads", "1"]
        for key, value in sorted(recipe.items()):
            command += [f"--{key.replace('_', '-')}", str(value)]
        folder.parent.mkdir(parents=True, exist_ok=True)
        _check_call(command, f"synthetic cell {cell.name}")
    _make_once(target, render)
    return target, identity


def _reencoded(folder, identity, quality, tool, setup):
    identity = content.digest({"jpeg": quality, "source": identity,
                               "tool_sha256": content.file_sha256(tool)})
    target = setup.work / "sequences" / f"jpeg{quality}-{identity[:16]}"

    def reencode(out):
        out.parent.mkdir(parents=True, exist_ok=True)
        _check_call([str(tool), str(folder), str(out), str(quality)], f"re-encoding {folder}")
    _make_once(target, reencode)
    return target, identity


def _read_list(path):
    """A TUM list file as (comment lines, data lines)."""
    comments, rows = [], []
    for line in Path(path).read_text().splitlines():
        (comments if line.startswith("#") or not line.strip() else rows).append(line)
    return comments, rows


def _write_list(path, comments, rows):
    Path(path).write_text("\n".join(comments + rows) + "\n")


def _sliced(folder, identity, start, setup):
    """The sequence from colour frame `start` on, with the depth and ground truth of that time
    span; image folders are linked, not copied."""
    identity = content.digest({"start": start, "source": identity})
    target = setup.work / "sequences" / f"from{start}-{identity[:16]}"

    def cut(out):
        out.mkdir(parents=True)
        comments, rgb = _read_list(folder / "rgb.txt")
        rgb = rgb[start:]
        first = float(rgb[0].split()[0]) - 0.05
        _write_list(out / "rgb.txt", comments, rgb)
        for name in ("depth.txt", "groundtruth.txt"):
            if (folder / name).exists():
                comments, rows = _read_list(folder / name)
                _write_list(out / name, comments, [r for r in rows if float(r.split()[0]) >= first])
        for name in ("rgb", "depth", "config.yaml", "body_to_camera.txt"):
            if (folder / name).exists():
                (out / name).symlink_to((folder / name).resolve())
    _make_once(target, cut)
    return target, identity


def _config_text(experiment, cell, variant, folder, setup):
    if cell.config:
        path = setup.repo / cell.config
        if not path.is_file():
            raise ExperimentError(f"{experiment.path}: cell '{cell.name}': config {cell.config} "
                                  f"not found in {setup.repo}")
        text = path.read_text()
        origin = cell.config
    elif (folder / "config.yaml").exists():
        text, origin = (folder / "config.yaml").read_text(), f"{cell.name}'s config.yaml"
    else:
        text, origin = None, None
    for owner, settings in ((f"cell '{cell.name}'", cell.config_set),
                            (f"variant '{variant.name}'", variant.config_set)):
        for key, value in settings.items():
            if text is None:
                raise ExperimentError(f"{experiment.path}: {owner}: set {key}: the cell has no "
                                      "config to change (give it config = ...)")
            try:
                text = set_config_key(text, key, value)
            except KeyError:
                raise ExperimentError(f"{experiment.path}: {owner}: set {key}: {origin} has no "
                                      "such key") from None
    return text


def set_config_key(text, dotted_key, value):
    """`text` (a YAML config) with the value of `dotted_key` (e.g. camera.depth_factor) replaced,
    comments and layout kept. Raises KeyError unless the key is there exactly once."""
    target = dotted_key.split(".")
    stack, lines, replaced = [], text.splitlines(), 0
    for index, line in enumerate(lines):
        stripped = line.lstrip()
        if not stripped or stripped.startswith("#") or ":" not in stripped:
            continue
        indent = len(line) - len(stripped)
        key = stripped.split(":", 1)[0].strip()
        while stack and stack[-1][0] >= indent:
            stack.pop()
        stack.append((indent, key))
        if [k for _, k in stack] == target:
            lines[index] = f"{' ' * indent}{key}: {_yaml_scalar(value)}"
            replaced += 1
    if replaced != 1:
        raise KeyError(dotted_key)
    return "\n".join(lines) + "\n"


def _yaml_scalar(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def _stretches(cell, folder, identity, setup):
    """The whole cell, then each declared stretch with its own ground-truth file."""
    ground_truth = folder / "groundtruth.txt"
    if not ground_truth.exists():
        return []
    body = folder / "body_to_camera.txt"
    body = str(body) if body.exists() else None
    stretches = [_evaluation(cell.name, ground_truth, body)]
    for stretch in cell.stretches:
        part = content.digest({"stretch": [stretch.first, stretch.last], "source": identity})
        target = setup.work / "sequences" / f"stretch-{part[:16]}.txt"
        if not target.exists():
            _write_stretch_ground_truth(folder, target, stretch.first, stretch.last)
        stretches.append(_evaluation(f"{cell.name}:{stretch.name}", target, body))
    return stretches


def _evaluation(name, ground_truth, body_to_camera):
    """One evaluation of a run: a name for the tables and an id by content (the ground truth and
    the body-to-camera transform), under which the result keeps it: another experiment's cell
    scored on the same ground truth reads the same evaluation."""
    identity = content.digest([content.file_sha256(ground_truth),
                               body_to_camera and content.file_sha256(body_to_camera)])
    return {"name": name, "id": identity[:16], "ground_truth": str(ground_truth),
            "body_to_camera": body_to_camera}


def _write_stretch_ground_truth(folder, target, first, last):
    """The ground truth of colour frames first..last-1 only: evaluating against it aligns and
    scores that stretch of the run on its own."""
    _, rgb = _read_list(folder / "rgb.txt")
    last = len(rgb) if last is None else min(last, len(rgb))
    t0 = float(rgb[first].split()[0]) - 0.02
    t1 = float(rgb[last - 1].split()[0]) + 0.02
    comments, rows = _read_list(folder / "groundtruth.txt")
    target.parent.mkdir(parents=True, exist_ok=True)
    temporary = target.with_name(f".{target.name}.{uuid.uuid4().hex}.tmp")
    _write_list(temporary, comments, [r for r in rows if t0 <= float(r.split()[0]) <= t1])
    temporary.replace(target)


def _image_split(experiment, cell, folder, identity, setup):
    """segment cells: the images named by the split file (or all), linked into one folder, with
    the masks beside them."""
    ids = None
    if cell.split:
        split_file = setup.repo / cell.split
        try:
            ids = json.loads(split_file.read_text())[cell.split_key]
        except (OSError, KeyError, ValueError) as error:
            raise ExperimentError(f"{experiment.path}: cell '{cell.name}': split {cell.split} "
                                  f"has no list '{cell.split_key}' ({error})") from None
    identity = content.digest({"images": identity, "ids": ids})
    target = setup.work / "sequences" / f"images-{identity[:16]}"

    def link(out):
        (out / "images").mkdir(parents=True)
        for image in sorted((folder / "images").iterdir()):
            if ids is None or int(image.stem) in ids:
                (out / "images" / image.name).symlink_to(image.resolve())
        (out / "masks").symlink_to((folder / "masks").resolve())
    _make_once(target, link)
    return Prepared(target, identity, None)


def _check_call(command, what):
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"{what}: {' '.join(command)} exited {result.returncode}: "
                           f"{result.stderr.strip()[-500:]}")
