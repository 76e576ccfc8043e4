"""The standard suites on synthetic stand-ins: a short `pspslam synth` sequence copied into the
official folder layout of a few TUM and Bonn sequences. The ones present are run, every other
one is listed as missing."""
import shutil
import subprocess

import pytest
from conftest import REPO, run_runner, section_tables


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
    rows = [line for line in section_tables(results, name) if line.startswith("| ")][1:]
    return completed, rows


def test_tum_suite_runs_what_is_there_and_lists_the_rest(stand_in, tmp_path, build):
    present = ["rgbd_dataset_freiburg3_walking_xyz", "rgbd_dataset_freiburg3_sitting_static"]
    completed, rows = run_suite("tum_dynamic", present, stand_in, tmp_path, build)
    run = [row for row in rows if row.startswith(("| fr3_walking_xyz ", "| fr3_sitting_static "))]
    assert len(run) == 2 and all("/30 |" in row for row in run), rows
    missing = [row for row in rows if "missing: " in row]
    assert len(missing) == 6
    assert "| fr3_walking_rpy | missing: rgbd_dataset_freiburg3_walking_rpy not in " in "\n".join(missing)
    assert "fr3_walking_halfsphere: missing (rgbd_dataset_freiburg3_walking_halfsphere not in" \
        in completed.stderr


def test_bonn_suite_lists_all_24_sequences(stand_in, tmp_path, build):
    completed, rows = run_suite("bonn_dynamic", ["rgbd_bonn_crowd"], stand_in, tmp_path, build)
    cells = [row.split(" | ")[0][2:] for row in rows]
    assert len(cells) == 24 and "crowd" in cells and "placing_nonobstructing_box3" in cells
    assert sum("missing: rgbd_bonn_" in row for row in rows) == 23
    assert "/30 |" in next(row for row in rows if row.startswith("| crowd |"))
