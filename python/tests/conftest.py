"""Shared fixtures: the CLI of the build under test and synthetic sequences made with it.

ctest (python/CMakeLists.txt) sets PYTHONPATH to the build's package and PSPSLAM_CLI to the
build's `pspslam` program; PSPSLAM_BUILD_DIR and PSPSLAM_SOURCE_DIR for the install and example
tests."""

import os
import pathlib
import subprocess

import pytest

import pspslam


def _required_env(name):
    value = os.environ.get(name)
    if not value:
        pytest.skip(f"{name} is not set (run through ctest, or set it by hand)")
    return value


@pytest.fixture(scope="session")
def cli():
    return _required_env("PSPSLAM_CLI")


@pytest.fixture(scope="session")
def source_dir():
    return pathlib.Path(_required_env("PSPSLAM_SOURCE_DIR"))


@pytest.fixture(scope="session")
def build_dir():
    return pathlib.Path(_required_env("PSPSLAM_BUILD_DIR"))


def synthesize(cli, folder, frames, seed):
    subprocess.run([cli, "-q", "synth", "--out", str(folder), "--frames", str(frames),
                    "--seed", str(seed)], check=True, stdout=subprocess.DEVNULL)
    return folder


@pytest.fixture(scope="session")
def synthetic_sequence(cli, tmp_path_factory):
    """The 60-frame synthetic sequence of seed 1 (people walking through a room)."""
    return synthesize(cli, tmp_path_factory.mktemp("synth") / "seq", 60, 1)


@pytest.fixture(scope="session")
def small_sequence(cli, tmp_path_factory):
    return synthesize(cli, tmp_path_factory.mktemp("small") / "seq", 12, 2)


@pytest.fixture(scope="session")
def cli_run(cli, synthetic_sequence, tmp_path_factory):
    """`pspslam run` on the synthetic sequence, deterministic (no --realtime): its output folder."""
    out = tmp_path_factory.mktemp("cli_run")
    subprocess.run([cli, "-q", "run", "--sequence", str(synthetic_sequence), "--out", str(out)],
                   check=True, stdout=subprocess.DEVNULL)
    return out


@pytest.fixture(scope="session")
def small_frames(small_sequence):
    return list(pspslam.read_sequence(small_sequence))
