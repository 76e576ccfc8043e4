"""The installed module imports from a clean prefix; the example runs on a synthetic sequence."""

import os
import subprocess
import sys

import pytest


def test_installed_module_imports_from_a_clean_prefix(build_dir, tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", str(build_dir), "--prefix", str(prefix)], check=True,
                   stdout=subprocess.DEVNULL)
    site = subprocess.run(
        ["cmake", "-N", "-L", str(build_dir)], check=True, capture_output=True, text=True).stdout
    folder = next(line.split("=", 1)[1] for line in site.splitlines()
                  if line.startswith("PSPSLAM_PYTHON_INSTALL_DIR:"))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    # No source tree, no build tree: only the prefix's package folder on the path.
    check = (
        "import pspslam, pathlib\n"
        "data = pathlib.Path(pspslam.data_dir())\n"
        "print(pathlib.Path(pspslam.__file__).parent)\n"
        "print(data)\n"
        "slam = pspslam.System(data / 'config' / 'bonn.yaml', mode='full')\n"
        "print(slam.mode)\n")
    env = {"PATH": "/usr/bin:/bin", "PYTHONPATH": str(prefix / folder), "HOME": str(elsewhere)}
    out = subprocess.run([sys.executable, "-c", check], cwd=elsewhere, env=env,
                         check=True, capture_output=True, text=True).stdout.splitlines()
    assert out[0] == str(prefix / folder / "pspslam")
    assert out[1] == str(prefix / "share" / "pspslam")
    assert out[2] == "full"  # the installed model loaded


def test_example_tracks_a_sequence(source_dir, small_sequence, tmp_path):
    pytest.importorskip("matplotlib")
    trajectory = tmp_path / "trajectory.txt"
    run = subprocess.run(
        [sys.executable, str(source_dir / "examples" / "track_sequence.py"), str(small_sequence),
         str(trajectory)], cwd=tmp_path, check=True, capture_output=True, text=True,
        env=dict(os.environ, MPLBACKEND="Agg"))
    assert trajectory.read_text().startswith("# pspslam trajectory")
    assert "ATE" in run.stdout
    assert (tmp_path / "trajectory.png").stat().st_size > 10000
