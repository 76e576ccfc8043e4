"""System(occupancy=True).occupancy_grid(): the 2D grid `pspslam run --export-grid` writes, as a
numpy array with its origin and resolution."""

import subprocess

import numpy as np
import pytest

import pspslam

RESOLUTION = 0.1  # coarser than the default: a quicker map, and a value the test can tell


def read_pgm(path):
    """A binary (P5) PGM with the header pspslam writes: magic, one comment, size, maximum."""
    data = path.read_bytes()
    header = data.split(b"\n", 4)
    width, height = (int(v) for v in header[2].split())
    pixels = np.frombuffer(header[4], dtype=np.uint8, count=width * height)
    return pixels.reshape(height, width)


def map_server_cells(pgm):
    """map_server trinary pixels as grid values, row 0 at the lowest y (the image's top row is
    the highest)."""
    cells = np.full(pgm.shape, -1, dtype=np.int8)
    cells[pgm == 0] = 100
    cells[pgm == 254] = 0
    return cells[::-1]


@pytest.fixture(scope="module")
def python_grid(synthetic_sequence):
    sequence = pspslam.read_sequence(synthetic_sequence)
    with pspslam.System(sequence, occupancy=True, occupancy_resolution=RESOLUTION) as slam:
        for _ in slam.track_frames(sequence):
            pass
    # After close: the map rebuilt at the final keyframe poses, as the CLI's export.
    return slam.occupancy_grid()


def test_the_grid_has_free_and_occupied_cells(python_grid):
    grid = python_grid["grid"]
    assert grid.dtype == np.int8 and grid.ndim == 2 and grid.size > 0
    assert set(np.unique(grid)) <= {-1, 0, 100}
    assert (grid == 0).any() and (grid == 100).any()
    assert python_grid["resolution"] == pytest.approx(RESOLUTION)
    assert len(python_grid["origin"]) == 2
    assert python_grid["T_world_grid"].shape == (4, 4)
    assert np.isfinite(python_grid["floor_height"])


def test_the_grid_is_the_one_the_cli_exports(cli, synthetic_sequence, python_grid, tmp_path):
    yaml = tmp_path / "grid.yaml"
    subprocess.run([cli, "-q", "run", "--sequence", str(synthetic_sequence), "--out",
                    str(tmp_path / "out"), "--occupancy-resolution", str(RESOLUTION),
                    "--export-grid", str(yaml)], check=True, stdout=subprocess.DEVNULL)
    cells = map_server_cells(read_pgm(tmp_path / "grid.pgm"))
    grid = python_grid["grid"]
    assert grid.shape == cells.shape
    assert (grid == cells).mean() >= 0.99
    text = yaml.read_text()
    assert f"resolution: {RESOLUTION:g}" in text
    x, y = python_grid["origin"]
    assert f"origin: [{x:g}, {y:g}, 0.0]" in text


def test_a_system_without_occupancy_has_no_grid(small_sequence):
    with pspslam.System(pspslam.read_sequence(small_sequence)) as slam:
        with pytest.raises(ValueError) as raised:
            slam.occupancy_grid()
    assert str(raised.value) == ("occupancy_grid: this System builds no occupancy map (make it "
                                 "with occupancy=True)")


def test_an_upside_down_band_names_the_keywords(small_sequence):
    with pspslam.System(pspslam.read_sequence(small_sequence), occupancy=True) as slam:
        with pytest.raises(ValueError, match=r"^min_height 1\.2\d* and max_height 0\.3\d*: the "
                                             r"height band is upside down"):
            slam.occupancy_grid(min_height=1.2, max_height=0.3)
