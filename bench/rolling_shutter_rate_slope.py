#!/usr/bin/env python3
"""Does a camera's rolling-shutter readout match what its images show? (numpy)

A run with `camera.rolling_shutter_readout: R` measures each frame's rotation rate from the skew
of its own keypoints (optimize/rolling_shutter_pose.h); the poses of the same run turn at a rate
that does not depend on R. If the sensor really reads its rows over R seconds, the two agree
(slope 1); if it reads them over R', the image rate is the pose rate times R'/R.

usage: bench/rolling_shutter_rate_slope.py RATES TRAJECTORY [HALF_WINDOW]
  RATES       lines "RATE timestamp wx wy wz" (rad/s, camera frame) printed by a build with
              bench/patches/print_rotation_rate.patch applied (`pspslam run ... 2>&1 | grep ^RATE`)
  TRAJECTORY  the same run's trajectory.txt
  HALF_WINDOW the pose rate is the rotation between frames i-h and i+h over their time (default 3)
Prints per camera axis the least-squares slope image rate / pose rate, their correlation and RMS.
"""
import sys

import numpy as np

from tum_numpy import rotation, so3_log


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    rates = np.array([[float(v) for v in line.split()[1:5]] for line in open(sys.argv[1])
                      if line.startswith("RATE ")])
    poses = [line.split() for line in open(sys.argv[2]) if not line.startswith("#")]
    stamps = np.array([float(p[0]) for p in poses])
    R_world_camera = [rotation(np.array([float(v) for v in p[4:8]])) for p in poses]
    h = int(sys.argv[3]) if len(sys.argv) == 4 else 3
    image, pose = [], []
    for t, wx, wy, wz in rates:
        i = int(np.argmin(np.abs(stamps - t)))
        if abs(stamps[i] - t) > 1e-3 or i - h < 0 or i + h >= len(stamps):
            continue
        turn = R_world_camera[i - h].T @ R_world_camera[i + h]
        pose.append(so3_log(turn) / (stamps[i + h] - stamps[i - h]))
        image.append([wx, wy, wz])
    image, pose = np.array(image), np.array(pose)
    print(f"{len(image)} frames; rates in deg/s")
    for axis, name in enumerate("xyz"):
        a, b = image[:, axis], pose[:, axis]
        print(f"camera {name} axis: slope image/pose {a @ b / (b @ b):.2f}, correlation "
              f"{np.corrcoef(a, b)[0, 1]:.2f}, RMS pose {np.degrees(np.sqrt(np.mean(b * b))):.1f}, "
              f"RMS image {np.degrees(np.sqrt(np.mean(a * a))):.1f}, RMS difference "
              f"{np.degrees(np.sqrt(np.mean((a - b) ** 2))):.1f}")


if __name__ == "__main__":
    main()
