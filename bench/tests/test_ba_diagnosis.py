"""tools/diagnosis/ba_keyframes.py: its map-file reader on hand-written files, its errors, and
the whole tool on a small synthetic run of the built CLI (skipped without one)."""
import csv
import importlib.util
import json
import math
import re
import struct
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
TOOL = REPO / "tools" / "diagnosis" / "ba_keyframes.py"
NO_ID = 2**64 - 1


def load_tool():
    spec = importlib.util.spec_from_file_location("ba_keyframes", TOOL)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


tool = load_tool()


def run_tool(*arguments):
    return subprocess.run([sys.executable, str(TOOL), *map(str, arguments)],
                          capture_output=True, text=True)


# --- the map file, written byte by byte as map_file.cpp writes version 1 ----------------------

def fnv1a64(data):
    value = 0xCBF29CE484222325
    for byte in data:
        value = ((value ^ byte) * 0x100000001B3) % 2**64
    return value


def keypoint(x, y, depth, point_id):
    return struct.pack("<5fifQ", x, y, 7.0, 12.5, 0.25, 1, depth, point_id)


def tiny_payload(keypoint_count=None):
    """One keyframe (id 4, frame 9) with three keypoints, two of them on the two map points."""
    camera = struct.pack("<5d3Id", 500.0, 501.0, 320.0, 240.0, 40.0, 640, 480, 8, 1.2)
    counts = struct.pack("<QQ", 1, 2)
    points = (struct.pack("<Q3dQQ", 11, 0.5, -0.25, 2.0, 4, 4) +
              struct.pack("<Q3dQQ", 12, 1.0, 0.0, 3.5, 4, 2))
    pose = [1, 0, 0, 0, 1, 0, 0, 0, 1, 0.1, 0.2, 0.3]
    keypoints = [keypoint(100.5, 50.25, 2.0, 11), keypoint(200, 60, -1.0, NO_ID),
                 keypoint(300, 70, 3.5, 12)]
    keyframe = struct.pack("<QQd12dQI", 4, 9, 123.5, *pose, NO_ID,
                           len(keypoints) if keypoint_count is None else keypoint_count)
    keyframe += b"".join(keypoints) + bytes(32 * len(keypoints))
    return camera + counts + points + keyframe


def map_bytes(payload, magic=b"PSPSLMAP"):
    return struct.pack("<8sIIQQ", magic, 1, 0, len(payload), fnv1a64(payload)) + payload


def test_map_reader_reads_a_hand_written_file(tmp_path):
    path = tmp_path / "tiny.pspmap"
    path.write_bytes(map_bytes(tiny_payload()))
    saved = tool.read_map(path)
    assert (saved.camera.fx, saved.camera.fy, saved.camera.width, saved.camera.height) == \
        (500.0, 501.0, 640, 480)
    assert list(saved.points["id"]) == [11, 12]
    assert list(saved.points["first_keyframe"]) == [4, 2]
    assert saved.points["position"][1].tolist() == [1.0, 0.0, 3.5]
    [keyframe] = saved.keyframes
    assert (keyframe.id, keyframe.frame_id, keyframe.timestamp, keyframe.parent) == \
        (4, 9, 123.5, NO_ID)
    assert keyframe.T_camera_world[:3, 3].tolist() == [0.1, 0.2, 0.3]
    assert list(keyframe.keypoints["point"]) == [11, NO_ID, 12]
    assert keyframe.keypoints["x"][0] == pytest.approx(100.5)
    assert keyframe.keypoints["depth"].tolist() == [2.0, -1.0, 3.5]


def test_map_reader_names_the_file_of_a_truncated_map(tmp_path):
    path = tmp_path / "cut.pspmap"
    path.write_bytes(map_bytes(tiny_payload())[:-40])
    with pytest.raises(tool.InputError, match=re.escape(str(path)) + ".*truncated"):
        tool.read_map(path)
    # A consistent header, but a keyframe announcing more keypoints than the payload holds.
    path.write_bytes(map_bytes(tiny_payload(keypoint_count=9)))
    with pytest.raises(tool.InputError, match=re.escape(str(path)) + ".*truncated.*keypoints"):
        tool.read_map(path)


def test_map_reader_refuses_a_bad_magic(tmp_path):
    path = tmp_path / "other.pspmap"
    path.write_bytes(map_bytes(tiny_payload(), magic=b"NOTAMAP!"))
    with pytest.raises(tool.InputError, match=re.escape(str(path)) + ".*bad magic"):
        tool.read_map(path)


def test_spearman_handles_ties_and_order():
    rho, _, n = tool.spearman([1, 2, 3, 4, 5], [10, 20, 30, 40, 50])
    assert (rho, n) == (pytest.approx(1.0), 5)
    rho, _, _ = tool.spearman([1, 2, 2, 3, math.nan], [3, 2, 2, 1, 7])
    assert rho == pytest.approx(-1.0)


def test_missing_keyframes_file_exits_2_naming_it(tmp_path):
    run, sequence = tmp_path / "run", tmp_path / "sequence"
    run.mkdir()
    sequence.mkdir()
    completed = run_tool("--run", run, "--sequence", sequence)
    assert completed.returncode == 2
    assert str(run / "keyframes.txt") in completed.stderr


# --- the whole tool on a synthetic run -------------------------------------------------------

@pytest.fixture(scope="module")
def synthetic_diagnosis(cli, tmp_path_factory):
    pytest.importorskip("PIL", reason="the tool reads PNGs with PIL (python3-pil)")
    work = tmp_path_factory.mktemp("ba_diagnosis")
    sequence, run = work / "sequence", work / "run"
    for command in (
            ["synth", "--out", sequence, "--frames", 90, "--bodies", 2, "--seed", 3,
             "--sensor", "kinect"],
            ["run", "--sequence", sequence, "--dynamic", "geometry", "--out", run,
             "--save-map", run / "map.pspmap"]):
        subprocess.run([str(cli), "-q", *map(str, command)], check=True, capture_output=True)
    completed = run_tool("--run", run, "--sequence", sequence, "--csv", work / "keyframes.csv",
                         "--markdown", work / "summary.md")
    assert completed.returncode == 0, completed.stderr
    with open(work / "keyframes.csv") as stream:
        rows = list(csv.DictReader(stream))
    return {"sequence": sequence, "run": run, "rows": rows, "stdout": completed.stdout,
            "markdown": (work / "summary.md").read_text()}


def keyframe_lines(run):
    return [line for line in (run / "keyframes.txt").read_text().splitlines()
            if line.strip() and not line.startswith("#")]


def test_one_row_per_keyframe(synthetic_diagnosis):
    assert len(synthetic_diagnosis["rows"]) == len(keyframe_lines(synthetic_diagnosis["run"]))


def test_keyframe_rmse_agrees_with_pspslam_eval(cli, synthetic_diagnosis):
    sequence, run = synthetic_diagnosis["sequence"], synthetic_diagnosis["run"]
    evaluation = subprocess.run(
        [str(cli), "eval", "--gt", str(sequence / "groundtruth.txt"), "--gt-body-to-camera",
         str(sequence / "body_to_camera.txt"), "--est", str(run / "keyframes.txt"), "--json"],
        check=True, capture_output=True, text=True)
    expected_mm = json.loads(evaluation.stdout)["ate"]["error_m"]["rmse"] * 1000
    reported_mm = float(re.search(r"after BA ([0-9.]+) mm", synthetic_diagnosis["markdown"])[1])
    assert reported_mm == pytest.approx(expected_mm, rel=0.05)


def test_shares_lie_between_0_and_1(synthetic_diagnosis):
    for row in synthetic_diagnosis["rows"]:
        for name, value in row.items():
            if (name.endswith("_share") or name == "person_change") and value != "":
                assert 0.0 <= float(value) <= 1.0, (name, row)


def test_person_share_comes_from_the_label_masks(synthetic_diagnosis):
    values = [row["person_share"] for row in synthetic_diagnosis["rows"]]
    assert any(value != "" and math.isfinite(float(value)) for value in values)
    assert "mask" in synthetic_diagnosis["markdown"]


def test_summary_names_run_and_sequence(synthetic_diagnosis):
    text = synthetic_diagnosis["stdout"]
    assert str(synthetic_diagnosis["run"]) in text and str(synthetic_diagnosis["sequence"]) in text
    assert text == synthetic_diagnosis["markdown"]
