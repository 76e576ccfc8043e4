"""The standard suites on synthetic stand-ins: a short `pspslam synth` sequence copied into the
official folder layout of a few TUM and Bonn sequences. The ones present are run, every other
one is listed as missing."""
import shutil
import subprocess

import pytest
from conftest import REPO, accuracy_rows, run_runner


@pytest.fixture(scope="module")
def stand_in(cli, tmp_path_factory):
    """A 40-frame synthetic sequence in the TUM layout (rgb.txt, depth.txt, groundtruth.txt)."""
    folder = tmp_path_factory.mktemp("stand_in") / "sequence"
    subprocess.run([str(cli), "-q", "synth", "--out", str(folder), "--frames", "40", "--bodies",
                    "1", "--seed", "5", "--threads", "1"], check=True)
    (folder / "config.yaml").unlink()  # a downloaded sequence has none: the suite's config applies
    return folder


def run_suite(name, present, stand_in, tmp_path, build):
    data = tmp_path / "data"
    for folder in present:
        shutil.copytree(stand_in, data / folder, symlinks=True)
    results = tmp_path / "results.md"
    completed = run_runner(REPO / "bench" / "experiments" / f"{name}.toml", "--data", data,
                           "--variants", "off", "--limit-frames", "30", "--work", tmp_path / "work",
                           "--results", results, build=build)
    return completed, accuracy_rows(results, name)


def test_tum_suite_runs_what_is_there_and_lists_the_rest(stand_in, tmp_path, build):
    present = ["rgbd_dataset_freiburg3_walking_xyz", "rgbd_dataset_freiburg3_sitting_static"]
    completed, rows = run_suite("tum_dynamic", present, stand_in, tmp_path, build)
    assert len(rows) == 8
    for cell in ("fr3_walking_xyz", "fr3_sitting_static"):
        assert rows[cell][0].endswith("/30"), rows
    missing = {cell: entries[0] for cell, entries in rows.items()
               if entries[0].startswith("missing: ")}
    assert len(missing) == 6
    assert missing["fr3_walking_rpy"].startswith(
        "missing: rgbd_dataset_freiburg3_walking_rpy not in ")
    assert "fr3_walking_halfsphere: missing (rgbd_dataset_freiburg3_walking_halfsphere not in" \
        in completed.stderr


def test_bonn_suite_lists_all_24_sequences(stand_in, tmp_path, build):
    _, rows = run_suite("bonn_dynamic", ["rgbd_bonn_crowd"], stand_in, tmp_path, build)
    assert len(rows) == 24 and "placing_nonobstructing_box3" in rows
    assert sum(entries[0].startswith("missing: rgbd_bonn_") for entries in rows.values()) == 23
    assert rows["crowd"][0].endswith("/30")
