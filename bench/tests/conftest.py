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


@pytest.fixture
def tiny_experiment(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY_EXPERIMENT)
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


def executed_runs(work):
    log = Path(work) / "executed.log"
    return log.read_text().splitlines() if log.exists() else []
