"""Fixtures of the runner's tests: the built CLI, tiny experiments and a way to run the runner.

The CLI is $PSPSLAM_CLI_PATH (ctest passes it), else build/apps/pspslam of this checkout; tests
that run it skip, saying so, when neither exists.
"""
import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
RUNNER = REPO / "bench" / "runner.py"
sys.path.insert(0, str(REPO / "bench"))

# Two synthetic cells of 40 frames, each run in two modes that need no network: four quick,
# deterministic runs.
TINY_EXPERIMENT = """
title = "Tiny"
modes = ["off", "geometry"]
base = "off"

[[cells]]
name = "tiny"
seeds = [1, 2]
synth = { frames = 40, bodies = 1 }
"""


@pytest.fixture(scope="session")
def cli():
    path = Path(os.environ.get("PSPSLAM_CLI_PATH", REPO / "build" / "apps" / "pspslam"))
    if not os.access(path, os.X_OK):
        pytest.skip(f"no built CLI at {path} (set PSPSLAM_CLI_PATH or build build/)")
    return path


@pytest.fixture(scope="session")
def build(cli):
    """A folder laid out as a build (apps/pspslam) around the CLI under test."""
    return cli.resolve().parent.parent


@pytest.fixture(scope="session")
def shared():
    """The project's shared folder; CI has it (PSPSLAM_REQUIRE_SHARED=1), so there a test that
    needs it fails instead of skipping."""
    path = Path(os.environ.get("PSPSLAM_SHARED", REPO.parent / "shared"))
    if not (path / "data" / "bonn_crowd_dev").is_dir():
        message = f"no shared folder with data/bonn_crowd_dev at {path} (set PSPSLAM_SHARED)"
        if os.environ.get("PSPSLAM_REQUIRE_SHARED") == "1":
            pytest.fail(message)
        pytest.skip(message)
    return path


def run_runner(*arguments, build=None, check=True, **popen):
    """Runs `runner.py run ...` with this interpreter; returns the CompletedProcess."""
    command = [sys.executable, str(RUNNER), "run", *map(str, arguments)]
    if build is not None:
        command += ["--build", str(build)]
    completed = subprocess.run(command, capture_output=True, text=True, **popen)
    if check and completed.returncode != 0:
        raise AssertionError(f"{' '.join(command)} exited {completed.returncode}:\n"
                             f"{completed.stderr[-3000:]}")
    return completed


def section_tables(results_file, name):
    """The tables of experiment `name`'s section: the lines that depend on results only (not the
    regenerate command, date, machine or load line)."""
    text = Path(results_file).read_text()
    body = text.split(f"<!-- begin experiment {name} -->", 1)[1].split(
        f"<!-- end experiment {name} -->", 1)[0]
    return [line for line in body.splitlines()
            if not line.startswith(("Regenerate:", "_")) and not line.startswith("![")]


def accuracy_rows(results_file, name):
    """The first table of experiment `name`'s section (ATE per cell and variant), as
    {row name: [entry per variant]}."""
    rows, started = {}, False
    for line in section_tables(results_file, name):
        if line.startswith("| cell |"):
            started = True
        elif started and line.startswith("| "):
            cells = [cell.strip() for cell in line.strip("|").split(" | ")]
            rows[cells[0]] = cells[1:]
        elif started and not line.startswith("|"):
            break
    return rows


def executed_runs(work):
    log = Path(work) / "executed.log"
    return log.read_text().splitlines() if log.exists() else []
