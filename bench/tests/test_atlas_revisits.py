"""tools/diagnosis/atlas_revisits.py on a hand-made circle: a revisit found where the second map
comes back round, none where it does not, and bad input named."""
import json
import math
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
TOOL = REPO / "tools" / "diagnosis" / "atlas_revisits.py"


def circle_sequence(folder, frames=360):
    """A camera on a 1 m circle looking outwards, one degree a frame."""
    folder.mkdir()
    lines = []
    for i in range(frames):
        a = math.radians(i)
        # Camera z along the radius: a rotation about the world y axis by (90° - a).
        half = (math.pi / 2 - a) / 2
        lines.append(f"{i / 30:.6f} {math.cos(a):.6f} 0 {math.sin(a):.6f} 0 {math.sin(half):.6f} 0 "
                     f"{math.cos(half):.6f}")
    (folder / "groundtruth.txt").write_text("\n".join(lines) + "\n")
    return folder


def run_with_maps(folder, maps):
    folder.mkdir()
    (folder / "stats.json").write_text(json.dumps({"atlas": {"maps": maps}}))
    return folder


def tool(*arguments):
    return subprocess.run([sys.executable, str(TOOL), *map(str, arguments)], capture_output=True,
                          text=True)


def test_a_second_map_that_comes_round_again_has_a_common_view(tmp_path):
    sequence = circle_sequence(tmp_path / "seq", frames=720)
    run = run_with_maps(tmp_path / "run", [{"id": 0, "first_frame": 0, "last_frame": 199},
                                           {"id": 1, "first_frame": 200, "last_frame": 719}])
    result = tool("--run", run, "--sequence", sequence)
    assert result.returncode == 0, result.stderr
    # Frame 360 + k is frame k again: the closest pair is exact, one turn apart.
    assert "map 0 (frames 0-199) and map 1 (frames 200-719): closest common view 0.000 m apart" \
        in result.stdout
    assert "0.0 degrees" in result.stdout


def test_a_second_map_that_never_returns_has_none(tmp_path):
    sequence = circle_sequence(tmp_path / "seq")
    run = run_with_maps(tmp_path / "run", [{"id": 0, "first_frame": 0, "last_frame": 99},
                                           {"id": 1, "first_frame": 100, "last_frame": 299}])
    result = tool("--run", run, "--sequence", sequence)
    assert result.returncode == 0, result.stderr
    assert result.stdout == ("map 0 (frames 0-99) and map 1 (frames 100-299): no common view "
                             "within 20 degrees away from the seam\n")
    # Views within a second of the seam are not counted, wider angles are.
    wide = tool("--run", run, "--sequence", sequence, "--max-angle", "90")
    assert "closest common view" in wide.stdout


def test_bad_input_names_the_file(tmp_path):
    sequence = circle_sequence(tmp_path / "seq")
    missing = tool("--run", tmp_path / "none", "--sequence", sequence)
    assert missing.returncode == 2
    assert f"{tmp_path / 'none' / 'stats.json'}: cannot read the run's stats.json" in missing.stderr
    old = run_with_maps(tmp_path / "old", None)
    (old / "stats.json").write_text("{}")
    result = tool("--run", old, "--sequence", sequence)
    assert result.returncode == 2
    assert "no atlas.maps" in result.stderr
    short = run_with_maps(tmp_path / "short", [{"id": 0, "first_frame": 0, "last_frame": 10},
                                               {"id": 1, "first_frame": 11, "last_frame": 400}])
    result = tool("--run", short, "--sequence", sequence)
    assert result.returncode == 2
    assert "360 poses, but the run tracked frame 400" in result.stderr
