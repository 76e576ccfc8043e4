"""Experiment files: every shipped one loads, and a bad one is refused with the file, the field
and a non-zero exit status."""
import subprocess
import sys

import pytest
from conftest import REPO, RUNNER

from pspbench import experiment, sequences

SHIPPED = sorted((REPO / "bench" / "experiments").glob("*.toml"))


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_shipped_experiment_loads(path):
    loaded = experiment.load(path)
    assert loaded.cells and loaded.variants
    assert loaded.base in [v.name for v in loaded.variants]


def test_standard_suites_list_every_sequence():
    tum = experiment.load(REPO / "bench" / "experiments" / "tum_dynamic.toml")
    bonn = experiment.load(REPO / "bench" / "experiments" / "bonn_dynamic.toml")
    assert len(tum.cells) == 8 and len(bonn.cells) == 24
    assert "rgbd_dataset_freiburg3_walking_halfsphere" in [c.location for c in tum.cells]
    assert "rgbd_bonn_placing_nonobstructing_box3" in [c.location for c in bonn.cells]
    assert [v.name for v in tum.variants] == ["off", "semantic", "geometry", "full"]


TOP = "title = 'Bad'\nmodes = ['off', 'geometry']\nbase = 'off'\n"
CELL = "[[cells]]\nname = 'a'\nsynth = { frames = 10 }\n"
BAD_FILES = [
    (TOP + "repeats = 'three'\n" + CELL, "repeats: expected an integer, got str 'three'"),
    (TOP + "repeats = 0\n" + CELL, "repeats: must be at least 1, got 0"),
    (TOP + "colour = 1\n" + CELL,
     "colour: unknown field (known here: base, cells, columns, description, exclusive, "
     "keyframe_table, kind, metric, mode, modes, record, repeats, spread_variant, title, "
     "variants)"),
    (TOP.replace("'geometry'", "'fast'") + CELL,
     "modes[1]: 'fast' is not one of off, semantic, geometry, full, exhaustive"),
    (TOP.replace("base = 'off'", "base = 'nothing'") + CELL,
     "base: 'nothing' is not a variant (variants: off, geometry)"),
    (TOP + CELL + "[variants.x]\nflags = '--realtime'\n",
     "variants.x.flags: expected a list, got str '--realtime'"),
    (TOP + CELL + "[[cells]]\nname = 'b'\nshared = 'x'\ndata = 'y'\n",
     "cells[1].name: cell 'b' needs exactly one of shared, data, synth, program (has shared, "
     "data)"),
    (TOP + CELL + "[[cells]]\nname = 'c'\nsynth = { frames = 'many' }\n",
     "cells[1].synth.frames: expected an integer, got str 'many'"),
]


@pytest.mark.parametrize("text, message", BAD_FILES, ids=[m.split(":")[0] for _, m in BAD_FILES])
def test_bad_experiment_is_refused_naming_file_and_field(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    completed = subprocess.run([sys.executable, str(RUNNER), "run", str(path)],
                               capture_output=True, text=True)
    assert completed.returncode == 2
    assert completed.stderr == f"runner.py: {path}: {message}\n"


def test_unreadable_and_invalid_toml(tmp_path):
    missing = tmp_path / "none.toml"
    completed = subprocess.run([sys.executable, str(RUNNER), "run", str(missing)],
                               capture_output=True, text=True)
    assert completed.returncode == 2
    assert completed.stderr == f"runner.py: {missing}: cannot read (No such file or directory)\n"
    broken = tmp_path / "broken.toml"
    broken.write_text("title = \n")
    completed = subprocess.run([sys.executable, str(RUNNER), "run", str(broken)],
                               capture_output=True, text=True)
    assert completed.returncode == 2
    assert completed.stderr.startswith(f"runner.py: {broken}: not valid TOML (")


def test_config_keys_are_set_in_place():
    text = "camera:\n  fx: 1\n  depth_factor: 5000  # units per metre\nsystem:\n  depth_factor: 1\n"
    changed = sequences.set_config_key(text, "camera.depth_factor", 4999)
    assert changed == "camera:\n  fx: 1\n  depth_factor: 4999\nsystem:\n  depth_factor: 1\n"
    with pytest.raises(KeyError):
        sequences.set_config_key(text, "camera.no_such_key", 1)
    with pytest.raises(KeyError):
        sequences.set_config_key(text, "depth_factor", 1)


def test_a_cell_s_args_reach_its_runs(tmp_path):
    """A monocular cell among RGB-D ones: its own flags follow the variant's on the command."""
    path = tmp_path / "cells.toml"
    path.write_text("title = 'Cells'\n[variants.full]\nmode = 'full'\nflags = ['--mask-margin', "
                    "'3']\n" + CELL + "args = ['--sensor', 'monocular']\n")
    completed = subprocess.run([sys.executable, str(RUNNER), "run", str(path), "--dry-run",
                                "--work", str(tmp_path / "work")], capture_output=True, text=True)
    assert completed.returncode == 0, completed.stderr
    assert "--dynamic full --mask-margin 3 --sensor monocular" in completed.stdout
