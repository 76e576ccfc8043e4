"""Cells made from the shared development clip: a late start (a slice with its own ground
truth), stretches scored on their own, and a variant that changes a config key."""
from conftest import accuracy_rows, run_runner

EXPERIMENT = """
title = "Dev clip cells"
base = "plain"

[variants.plain]
mode = "off"

[variants.depth_4999]
mode = "off"
set = { "camera.depth_factor" = 4999 }

[[cells]]
name = "dev_end"
shared = "data/bonn_crowd_dev"
config = "config/bonn.yaml"
start = 370
stretches = [ { name = "first_half", first = 0, last = 15 }, { name = "second_half", first = 15 } ]
"""


def test_slice_stretches_and_config_keys(shared, build, tmp_path):
    experiment = tmp_path / "dev_cells.toml"
    experiment.write_text(EXPERIMENT)
    results = tmp_path / "results.md"
    run_runner(experiment, "--shared", shared, "--work", tmp_path / "work", "--results", results,
               "--jobs", "2", build=build)
    rows = accuracy_rows(results, "dev_cells")
    assert list(rows) == ["dev_end", "dev_end:first_half", "dev_end:second_half"]
    # The 30 frames from frame 370 on; each half is aligned and scored on its own poses.
    assert all(entry.endswith("/30") for entry in rows["dev_end"])
    for half in ("first_half", "second_half"):
        poses = [int(entry.split(" · ")[1].split()[0]) for entry in rows[f"dev_end:{half}"]]
        assert all(10 <= count <= 16 for count in poses), rows
    configs = sorted(path.read_text() for path in
                     (tmp_path / "work" / "runs").glob("*/attempt-*/config.yaml"))
    assert ["depth_factor: 4999" in text for text in configs].count(True) == 1
    assert ["depth_factor: 5000" in text for text in configs].count(True) == 1
