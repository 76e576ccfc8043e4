#!/usr/bin/env python3
"""Track a sequence folder from Python and write its trajectory.

    examples/track_sequence.py SEQUENCE_DIR OUT_TRAJECTORY.txt [--config CONFIG] [--mode MODE]

Reads a TUM/Bonn, KITTI or EuRoC folder, tracks every frame, writes the final camera-to-world
poses as a TUM trajectory (the same bytes `pspslam run` writes to trajectory_refined.txt, the file
to evaluate), prints the ATE when the folder has ground truth, and saves OUT_TRAJECTORY.png: the trajectory seen from above and the
frame with the most dynamic pixels, its dynamic mask in red.
"""

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
import numpy as np  # noqa: E402

import pspslam  # noqa: E402


def track(sequence, mode):
    """The final trajectory, and (image, mask) of the frame with the most dynamic pixels."""
    busiest, most_dynamic = None, -1
    with pspslam.System(sequence, mode=mode) as slam:
        for frame, result in slam.track_frames(sequence):
            # result.pose is the frame as tracked now (trajectory.txt); refined_poses() below
            # moves every frame with the bundle-adjusted keyframes once the run is over.
            dynamic = np.count_nonzero(result.mask)
            if dynamic > most_dynamic:
                # Views, not copies: they keep the frame's pixels and the mask alive.
                busiest, most_dynamic = (frame.image, result.mask), dynamic
    return slam.refined_poses(), busiest


def plot(path, trajectory, ground_truth, ate, busiest):
    figure, (top, picture) = plt.subplots(1, 2, figsize=(12, 5))
    positions = trajectory[1][:, :3, 3]
    if ate is not None:
        # The estimate in the ground truth's frame, moved by the ATE's alignment.
        positions = ate["scale"] * positions @ ate["rotation"].T + ate["translation"]
        truth = ground_truth[1][:, :3, 3]
        top.plot(truth[:, 0], truth[:, 1], color="0.75", linewidth=4, label="ground truth")
        top.set_title(f"ATE rmse {100 * ate['rmse']:.2f} cm")
    top.plot(positions[:, 0], positions[:, 1], color="tab:blue", label="pspslam")
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x (m)")
    top.set_ylabel("y (m)")
    top.legend()
    image, mask = busiest
    picture.imshow(image[:, :, ::-1])  # BGR -> RGB
    picture.imshow(np.ma.masked_equal(mask, 0), cmap=ListedColormap(["red"]), alpha=0.45)
    picture.set_title(f"dynamic mask ({np.count_nonzero(mask)} pixels)")
    picture.axis("off")
    figure.tight_layout()
    figure.savefig(path, dpi=100)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequence", type=pathlib.Path, help="sequence folder")
    parser.add_argument("out", type=pathlib.Path, help="TUM trajectory to write")
    parser.add_argument("--config", help="camera config (default: SEQUENCE/config.yaml)")
    parser.add_argument("--mode", default="full",
                        help="off | semantic | geometry | full | exhaustive | auto")
    args = parser.parse_args()

    sequence = pspslam.read_sequence(args.sequence, config=args.config)
    trajectory, busiest = track(sequence, args.mode)
    pspslam.write_trajectory(args.out, trajectory)
    print(f"{len(trajectory[0])} of {len(sequence)} frames tracked: {args.out}")
    ground_truth = sequence.ground_truth
    ate = None
    if ground_truth is not None and len(trajectory[0]) >= 3:
        ate = pspslam.ate(ground_truth, trajectory)
        print(f"ATE rmse {100 * ate['rmse']:.2f} cm over {ate['count']} poses")
    plot_file = args.out.with_suffix(".png")
    plot(plot_file, trajectory, ground_truth, ate, busiest)
    print(f"plot: {plot_file}")


if __name__ == "__main__":
    main()
