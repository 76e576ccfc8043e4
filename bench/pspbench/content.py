"""Content identities: what makes a build, a config, a data folder or a run what it is.

Runs and their results are keyed by these digests, never by paths or dates, so a result is
reused exactly when the same binary ran the same data with the same config and flags.
"""
import hashlib
import json
import os
from pathlib import Path

LIST_FILES = ("rgb.txt", "depth.txt", "groundtruth.txt", "right.txt", "times.txt", "calib.txt",
              "config.yaml", "body_to_camera.txt")


def digest(value):
    """SHA-256 of a JSON-able value, independent of dict order."""
    text = json.dumps(value, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def file_sha256(path):
    hasher = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            hasher.update(block)
    return hasher.hexdigest()


def folder_identity(folder):
    """A data folder's identity: the content of its list files (timestamps, ground truth, config)
    and the name and size of every other file. Hashing every image of a long recording would
    cost more than some runs; a changed image that keeps its size is the one thing it misses."""
    folder = Path(folder)
    entries = []
    for directory, subfolders, files in os.walk(folder, followlinks=True):
        subfolders.sort()
        for name in sorted(files):
            path = Path(directory) / name
            relative = str(path.relative_to(folder))
            if name in LIST_FILES and Path(directory) == folder:
                entries.append([relative, file_sha256(path)])
            else:
                entries.append([relative, path.stat().st_size])
    return digest(entries)


def tree_sha256(folder):
    """Content digest of every file under a folder (small trees: the shipped models)."""
    folder = Path(folder)
    if not folder.is_dir():
        return None
    return digest([[str(p.relative_to(folder)), file_sha256(p)]
                   for p in sorted(folder.rglob("*")) if p.is_file()])
