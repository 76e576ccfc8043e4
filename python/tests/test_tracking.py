"""The module against the CLI: same trajectory bytes, masks as documented, the GIL released."""

import threading

import numpy as np

import pspslam


def test_trajectory_and_people_are_those_of_the_cli(synthetic_sequence, cli_run, tmp_path):
    sequence = pspslam.read_sequence(synthetic_sequence)
    timestamps, poses, people = [], [], []
    with pspslam.System(sequence) as slam:
        for frame, result in slam.track_frames(sequence):
            if result.pose is not None:
                timestamps.append(frame.timestamp)
                poses.append(result.pose)
            people += [(frame.timestamp, p["id"], *p["position"], p["visible_pixels"])
                       for p in result.people]
    ours = tmp_path / "trajectory.txt"
    pspslam.write_trajectory(ours, (np.array(timestamps), np.array(poses)))
    expected = (cli_run / "trajectory.txt").read_bytes()
    assert len(timestamps) > 50
    assert ours.read_bytes() == expected
    refined = tmp_path / "trajectory_refined.txt"
    pspslam.write_trajectory(refined, slam.refined_poses())
    assert refined.read_bytes() == (cli_run / "trajectory_refined.txt").read_bytes()
    # people.csv: frame,timestamp,id,x,y,z,vx,vy,vz,extent,visible_pixels
    rows = [line.split(",") for line in (cli_run / "people.csv").read_text().splitlines()[1:]]
    assert len(people) == len(rows) > 0
    for ours_row, row in zip(people, rows):
        assert ours_row[1] == int(row[2]) and ours_row[5] == int(row[10])
        np.testing.assert_allclose(ours_row[2:5], [float(v) for v in row[3:6]], atol=1e-4)


def test_numpy_frames_track_as_the_reader_frames(small_sequence, small_frames):
    """track(image, depth, timestamp=...) from plain arrays, one by one, gives the poses of the
    reader's frames fed ahead (track_frames): the arrays path changes nothing."""
    sequence = pspslam.read_sequence(small_sequence)
    with pspslam.System(sequence) as slam:
        ahead = [result.pose for _, result in slam.track_frames(small_frames)]
    with pspslam.System(sequence) as slam:
        plain = [slam.track(np.array(f.image), np.array(f.depth), timestamp=f.timestamp).pose
                 for f in small_frames]
    assert len(ahead) == len(plain)
    for a, b in zip(ahead, plain):
        assert (a is None) == (b is None)
        if a is not None:
            np.testing.assert_array_equal(a, b)


def test_mask_is_a_read_only_uint8_view_of_the_frame_size(small_sequence, small_frames):
    with pspslam.System(pspslam.read_sequence(small_sequence)) as slam:
        results = [result for _, result in slam.track_frames(small_frames)]
    height, width = small_frames[0].image.shape[:2]
    for result in results:
        mask = result.mask
        assert mask.shape == (height, width)
        assert mask.dtype == np.uint8
        assert not mask.flags.writeable
    # People walk through the synthetic room: some frame has dynamic pixels.
    assert any(np.count_nonzero(r.mask) > 0 for r in results)
    assert {r.state for r in results} <= {"ok", "lost", "not_initialized"}
    # The view keeps the system's mask alive after its result is gone.
    mask, expected = results[-1].mask, results[-1].mask.copy()
    del results
    np.testing.assert_array_equal(mask, expected)


def test_pose_state_keypoints_and_map(small_sequence, small_frames, tmp_path):
    sequence = pspslam.read_sequence(small_sequence)
    with pspslam.System(sequence, keypoints=True) as slam:
        results = [result for _, result in slam.track_frames(small_frames)]
        last = results[-1]
        assert last.state == "ok"
        assert last.pose.shape == (4, 4)
        np.testing.assert_allclose(last.pose[3], [0, 0, 0, 1])
        assert last.keypoints.shape[1] == 2 and last.keypoints.dtype == np.float32
        assert last.fates.shape == (len(last.keypoints),)
        assert {pspslam.FATES[f] for f in last.fates} >= {"tracked"}
        points = slam.map_points()
        assert points.ndim == 2 and points.shape[1] == 3 and len(points) > 100
        stamps, poses = slam.keyframe_poses()
        assert len(stamps) >= 1 and poses.shape == (len(stamps), 4, 4)
        counts = slam.save_map(tmp_path / "map.bin")
    assert counts[0] == len(stamps)
    # A saved map loads through the constructor and the first frame is relocalised in it.
    with pspslam.System(sequence, load_map=tmp_path / "map.bin", localization=True) as slam:
        result = slam.track(small_frames[5])
        assert result.state == "ok"


def test_other_threads_run_while_a_frame_is_tracked(small_sequence, small_frames):
    counter = 0
    running = threading.Event()
    stop = threading.Event()

    def count():
        nonlocal counter
        running.set()
        while not stop.is_set():
            counter += 1

    with pspslam.System(pspslam.read_sequence(small_sequence)) as slam:
        thread = threading.Thread(target=count)
        thread.start()
        running.wait()
        during = []
        for frame in small_frames:
            before = counter
            slam.track(frame)
            during.append(counter - before)
        stop.set()
        thread.join()
    # With the GIL held for the whole frame the counter could not move while track() runs.
    assert sum(during) > 1000, during


def test_ate_and_rpe_match_the_cli_eval(synthetic_sequence, cli_run):
    gt = pspslam.read_trajectory(synthetic_sequence / "groundtruth.txt")
    est = pspslam.read_trajectory(cli_run / "trajectory.txt")
    ate = pspslam.ate(gt, est)
    assert 0 < ate["rmse"] < 0.05 and ate["count"] > 50
    rows = np.loadtxt(cli_run / "trajectory.txt")
    assert pspslam.ate(gt, rows)["rmse"] == ate["rmse"]
    rpe = pspslam.rpe(gt, est, delta=10, unit="f")
    assert rpe["translation"]["count"] > 0


def test_tracking_lost_for_long_starts_a_new_map(synthetic_sequence):
    """Black frames lose tracking; without relocalisation, once new_map_after seconds have passed
    the next frame with enough depth starts map 1, and the frames after it are tracked there."""
    sequence = pspslam.read_sequence(synthetic_sequence)
    frames = list(sequence)
    results = []
    with pspslam.System(sequence, mode="off", relocalization=False, new_map_after=0.2) as slam:
        for index, frame in enumerate(frames):
            image, depth = np.array(frame.image), np.array(frame.depth)
            if 20 <= index < 30:  # a third of a second without a picture
                image, depth = np.zeros_like(image), np.zeros_like(depth)
            results.append(slam.track(image, depth, timestamp=frame.timestamp))
    assert all(r.map_id == 0 and r.pose is not None for r in results[1:20])
    assert all(r.pose is None for r in results[20:30])
    assert results[30].new_map and results[30].method == "initialization"
    assert sum(r.new_map for r in results) == 1
    assert all(r.map_id == 1 and r.pose is not None for r in results[30:])
