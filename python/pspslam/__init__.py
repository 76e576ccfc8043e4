"""pspslam from Python: track numpy frames, read poses, masks and the map, evaluate.

    import pspslam
    with pspslam.System("config/bonn.yaml", mode="full") as slam:
        result = slam.track(bgr, depth, timestamp=t)   # uint8 HxWx3 BGR, uint16 raw or float32 m
        result.pose, result.state, result.mask         # 4x4 camera-to-world or None, 'ok', HxW uint8

Images are uint8 HxWx3 BGR (or HxW gray without semantics); depth is HxW uint16 in the sensor's
raw units (divided by the config's depth_factor, as the sequence readers do) or float32 metres.
Arrays must be C-contiguous: nothing is converted behind your back, bad input raises ValueError
or TypeError naming the argument. The GIL is released while a frame is processed.
"""

from ._pspslam import (  # noqa: F401
    FATES,
    Error,
    Frame,
    Result,
    Sequence,
    System,
    __version__,
    ate,
    data_dir,
    read_trajectory,
    rpe,
    run_options,
    write_trajectory,
)

__all__ = [
    "FATES", "Error", "Frame", "Result", "Sequence", "System", "ate", "data_dir",
    "read_sequence", "read_trajectory", "rpe", "run_options", "track_frames", "write_trajectory",
]


def read_sequence(folder, config=None, sensor=None, max_frames=0):
    """A TUM/Bonn, KITTI or EuRoC folder as `pspslam run` opens it: len(), indexing and iteration
    give Frames decoded on demand; .ground_truth is (timestamps, poses) or None. Without `config`
    the folder's own config.yaml is used (synthetic sequences ship one)."""
    return Sequence(folder, config=config, sensor=sensor, max_frames=max_frames)


def track_frames(system, frames):
    """Tracks `frames` (Frames, e.g. a read_sequence) and yields (frame, result) pairs.

    Each frame is announced one ahead, as `pspslam run` does, so that the network segments the
    next frame while this one is tracked: the same results as track() one by one, sooner."""
    iterator = iter(frames)
    current = next(iterator, None)
    if current is not None:
        system.announce(current)
    while current is not None:
        upcoming = next(iterator, None)
        if upcoming is not None:
            system.announce(upcoming)
        yield current, system.track(current)
        current = upcoming


def _enter(self):
    return self


def _exit(self, *exc):
    self.shutdown()
    return False


System.__enter__ = _enter
System.__exit__ = _exit
System.track_frames = track_frames
