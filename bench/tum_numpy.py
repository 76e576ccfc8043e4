"""Small numpy helpers shared by the bench scripts that read TUM trajectories themselves
(common_frames_ate.py, keyframe_error_split.py, loop_keyframe_states.py, placed_frames_error.py,
rolling_shutter_rate_slope.py). Scripts that must
stay independent of our code and of each other (independent_ate.py) do not use it.
Needs Debian's python3-numpy (run the scripts with /usr/bin/python3)."""
import numpy as np


def load_positions(path, decimals=None):
    """{timestamp: position} of a TUM file; `decimals` rounds the timestamps used as keys (so two
    runs' stamps of the same frame compare equal)."""
    poses = {}
    for line in open(path):
        if line.startswith("#") or not line.strip():
            continue
        values = [float(x) for x in line.split()]
        stamp = values[0] if decimals is None else round(values[0], decimals)
        poses[stamp] = np.array(values[1:4])
    return poses


def umeyama(P, Q, with_scale):
    """s, R, t with Q ≈ s R P + t (least squares; s = 1 unless `with_scale`)."""
    mp, mq = P.mean(0), Q.mean(0)
    U, S, Vt = np.linalg.svd((P - mp).T @ (Q - mq) / len(P))
    D = np.eye(3)
    D[2, 2] = np.sign(np.linalg.det(Vt.T @ U.T))
    R = Vt.T @ D @ U.T
    s = (S * np.diag(D)).sum() / ((P - mp) ** 2).sum(1).mean() if with_scale else 1.0
    return s, R, mq - s * R @ mp


def rotation(q):
    """Rotation matrix of a quaternion given as x, y, z, w (TUM order), normalised first."""
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def so3_log(R):
    """Rotation vector (axis times angle) of R."""
    angle = np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))
    if angle < 1e-9:
        return np.zeros(3)
    return angle / (2 * np.sin(angle)) * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0],
                                                   R[1, 0] - R[0, 1]])
