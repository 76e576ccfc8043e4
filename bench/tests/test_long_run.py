"""tools/diagnosis/long_run.py on a hand-made run: one alignment of the whole run, each window's
error, map size, memory and latency, and bad input named."""
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
TOOL = REPO / "tools" / "diagnosis" / "long_run.py"
HEADER = ("index,timestamp,state,method,keypoints,inliers,keyframe,extraction_ms,tracking_ms,"
          "local_ba_ms,mapping_queue,extraction_cpu_ms,tracking_cpu_ms,flow_ms,semantic_wait_ms,"
          "mask_age,geometry_ms,tested,dynamic,masked_keypoints,culled_points,arrival_to_pose_ms,"
          "keyframes_in_map,map_points,rss_mib")


def tool(*arguments):
    return subprocess.run([sys.executable, str(TOOL), *map(str, arguments)], capture_output=True,
                          text=True)


def make_run(tmp_path, latency=True):
    """Six frames in the plane z = 0 (frames 3 and 4 at the same place). The marker body sits 1 m
    behind the camera (body_to_camera t = (0, 0, 1)); the estimate is the camera path shifted by
    (5, 0, 0), which the alignment removes, with +3 mm and -3 mm in z on frames 3 and 4: they
    cancel in the alignment, so those two frames keep an error of 3 mm."""
    sequence, run = tmp_path / "seq", tmp_path / "run"
    sequence.mkdir()
    run.mkdir()
    gt, online, timing = [], [], [HEADER]
    places = [(0, 0), (0.1, 0), (0.1, 0.1), (0, 0.1), (0, 0.1), (0.2, 0.2)]
    for i, (x, y) in enumerate(places):
        t = 0.1 * i
        gt.append(f"{t:.6f} {x} {y} -1 0 0 0 1")
        dz = {3: 0.003, 4: -0.003}.get(i, 0.0)
        online.append(f"{t:.6f} {5 + x} {y} {dz} 0 0 0 1")
        arrival = f"{10 + i}" if latency else ""
        timing.append(f"{i},{t:.6f},ok,motion,1,1,0,1,1,0,0,1,1,0,0,0,0,0,0,0,0,{arrival},"
                      f"{2 + i},{100 * i},{50 + i}.5")
    (sequence / "groundtruth.txt").write_text("\n".join(gt) + "\n")
    (sequence / "body_to_camera.txt").write_text("# T_body_camera\n0 0 1 0 0 0 1\n")
    (run / "trajectory.txt").write_text("\n".join(online) + "\n")
    (run / "trajectory_refined.txt").write_text("\n".join(online[:3]) + "\n")
    (run / "timing.csv").write_text("\n".join(timing) + "\n")
    return run, sequence


def test_each_window_is_scored_after_one_alignment_of_the_whole_run(tmp_path):
    run, sequence = make_run(tmp_path)
    markdown = tmp_path / "table.md"
    result = tool(run, "--sequence", sequence, "--minute-frames", 3, "--markdown", markdown)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    # Frames 0-2 are exact; frames 3-5 have errors 3, 3 and 0 mm: RMSE 3 sqrt(2/3) = 2.4 mm.
    # The refined file has frames 0-2 only. Latency p99 of 10, 11, 12 ms: 11.98 ms.
    assert lines[2] == "| 0–2 | 0.0 | 0.0 | 0.0 | 0.0 | 4 | 200 | 52.5 | 11.0 | 12.0 |"
    assert lines[3] == "| 3–5 | 2.4 | 3.0 | – | – | 7 | 500 | 55.5 | 14.0 | 15.0 |"
    assert markdown.read_text() == result.stdout


def test_a_run_without_arrival_times_has_no_latency(tmp_path):
    run, sequence = make_run(tmp_path, latency=False)
    result = tool(run, "--sequence", sequence, "--minute-frames", 6)
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[2].endswith("| 7 | 500 | 55.5 | – | – |")


def test_a_timing_file_without_the_map_columns_is_named(tmp_path):
    run, sequence = make_run(tmp_path)
    (run / "timing.csv").write_text("index,timestamp,arrival_to_pose_ms\n0,0.0,\n")
    result = tool(run, "--sequence", sequence)
    assert result.returncode == 2
    assert result.stderr == (f"long_run.py: {run / 'timing.csv'}: no column keyframes_in_map, "
                             "map_points, rss_mib (a run of an older build?)\n")


def test_a_bad_ground_truth_is_named(tmp_path):
    run, sequence = make_run(tmp_path)
    (sequence / "groundtruth.txt").write_text("0 1 2\n")
    result = tool(run, "--sequence", sequence)
    assert result.returncode == 2
    assert result.stderr == (f"long_run.py: {sequence / 'groundtruth.txt'}: expected 8 columns "
                             "(t tx ty tz qx qy qz qw), got 3\n")


def test_the_plot_is_written_as_a_png(tmp_path):
    run, sequence = make_run(tmp_path)
    picture = tmp_path / "long_run.png"
    result = tool(run, "--sequence", sequence, "--minute-frames", 3, "--plot", picture)
    assert result.returncode == 0, result.stderr
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_window_of_no_frames_is_refused(tmp_path):
    run, sequence = make_run(tmp_path)
    result = tool(run, "--sequence", sequence, "--minute-frames", 0)
    assert result.returncode == 2
    assert result.stderr.endswith("error: --minute-frames: must be at least 1, got 0\n")
