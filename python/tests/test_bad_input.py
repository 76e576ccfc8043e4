"""Bad input raises TypeError / ValueError naming the argument and what was expected."""

import re

import numpy as np
import pytest

import pspslam


@pytest.fixture(scope="module")
def geometry_system(small_sequence):
    """Without semantics gray images are allowed; the cheapest system to feed."""
    with pspslam.System(pspslam.read_sequence(small_sequence), mode="geometry") as slam:
        yield slam


@pytest.fixture(scope="module")
def frame(small_frames):
    return small_frames[0]


def image_and_depth(frame):
    return np.array(frame.image), np.array(frame.depth)


CASES = {
    "image not an array": (
        lambda f: ([[0, 0, 0]], np.array(f.depth), {}), TypeError,
        "image: expected a numpy array (uint8 HxWx3 BGR or uint8 HxW gray), got list"),
    "image float": (
        lambda f: (np.array(f.image, dtype=np.float32), np.array(f.depth), {}), TypeError,
        "image: expected uint8 HxWx3 BGR or uint8 HxW gray, got dtype float32"),
    "image four channels": (
        lambda f: (np.zeros(f.image.shape[:2] + (4,), np.uint8), np.array(f.depth), {}),
        ValueError,
        "image: expected uint8 HxWx3 BGR or uint8 HxW gray, got <HW>x4 uint8"),
    "image channels first": (
        lambda f: (np.ascontiguousarray(np.array(f.image).transpose(2, 0, 1)),
                   np.array(f.depth), {}), ValueError,
        "image: expected uint8 HxWx3 BGR or uint8 HxW gray, got 3x<HW> uint8 "
        "(channels first?)"),
    "image not contiguous": (
        lambda f: (np.array(f.image)[:, ::-1], np.array(f.depth), {}), ValueError,
        "image: expected a C-contiguous array, got <HW>x3 uint8 with other strides (a slice "
        "or transpose; numpy.ascontiguousarray makes a contiguous copy)"),
    "image of another size": (
        lambda f: (np.zeros((120, 160, 3), np.uint8), np.zeros((120, 160), np.float32), {}),
        ValueError, "image: expected the camera's size in CONFIG, <WH> (width x height), "
        "got 160x120"),
    "depth missing": (
        lambda f: (np.array(f.image), None, {}), ValueError,
        "depth: the rgbd sensor needs one, got None"),
    "depth float64": (
        lambda f: (np.array(f.image), np.array(f.depth, dtype=np.float64), {}), TypeError,
        "depth: expected HxW uint16 raw depth units or HxW float32 metres, got dtype float64"),
    "depth with channels": (
        lambda f: (np.array(f.image), np.zeros(f.image.shape, np.uint16), {}), ValueError,
        "depth: expected HxW uint16 raw depth units or HxW float32 metres, got <HW>x3 "
        "uint16"),
    "depth not contiguous": (
        lambda f: (np.array(f.image), np.asfortranarray(f.depth), {}), ValueError,
        "depth: expected a C-contiguous array, got <HW> float32 with other strides (a slice "
        "or transpose; numpy.ascontiguousarray makes a contiguous copy)"),
    "depth of another size": (
        lambda f: (np.array(f.image), np.zeros((480, 641), np.uint16), {}), ValueError,
        "depth: expected the image's size <WH> (width x height), got 641x480"),
    "right on an rgbd system": (
        lambda f: (np.array(f.image), np.array(f.depth), {"right": np.array(f.gray)}),
        ValueError, "right: the rgbd sensor reads none, expected None"),
    "timestamp missing": (
        lambda f: (np.array(f.image), np.array(f.depth), {"timestamp": None}), TypeError,
        "timestamp: expected seconds as a number, got NoneType"),
    "timestamp text": (
        lambda f: (np.array(f.image), np.array(f.depth), {"timestamp": "1.0"}), TypeError,
        "timestamp: expected seconds as a number, got str"),
    "timestamp not finite": (
        lambda f: (np.array(f.image), np.array(f.depth), {"timestamp": float("nan")}),
        ValueError, "timestamp: expected a finite number of seconds, got nan"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_input_raises_with_its_message(case, geometry_system, frame, small_sequence):
    make, error, message = CASES[case]
    image, depth, extra = make(frame)
    extra.setdefault("timestamp", 1e9)
    height, width = frame.image.shape[:2]
    message = (message.replace("CONFIG", str(small_sequence / "config.yaml"))
               .replace("<HW>", f"{height}x{width}").replace("<WH>", f"{width}x{height}"))
    with pytest.raises(error, match="^" + re.escape(message) + "$"):
        geometry_system.track(image, depth, **extra)


def test_timestamps_going_back_raise(small_sequence, small_frames):
    with pspslam.System(pspslam.read_sequence(small_sequence), mode="off") as slam:
        slam.track(small_frames[1])
        image, depth = image_and_depth(small_frames[0])
        with pytest.raises(ValueError, match=re.escape(
                "timestamp: expected a time after the previous frame's "
                f"{small_frames[1].timestamp:f}, got {small_frames[0].timestamp:f}")):
            slam.track(image, depth, timestamp=small_frames[0].timestamp)
        with pytest.raises(ValueError, match="^timestamp: expected a time after"):
            slam.track(small_frames[1])  # the same time again


def test_gray_image_needs_a_mode_without_semantics(small_sequence, frame):
    with pspslam.System(pspslam.read_sequence(small_sequence), mode="full") as slam:
        with pytest.raises(ValueError, match="^" + re.escape(
                f"image: expected uint8 HxWx3 BGR, got {frame.gray.shape[0]}x"
                f"{frame.gray.shape[1]} uint8") + "$"):
            slam.track(np.array(frame.gray), np.array(frame.depth), timestamp=1.0)


def test_gray_image_tracks_without_semantics(geometry_system, small_frames):
    last = small_frames[-1]
    result = geometry_system.track(np.array(last.gray), np.array(last.depth),
                                   timestamp=last.timestamp + 1e6)
    assert result.state in ("ok", "lost")


def test_raw_depth_is_scaled_by_the_config(small_sequence, small_frames):
    """uint16 depth in sensor units reads as the reader's float32 metres (config depth_factor)."""
    sequence = pspslam.read_sequence(small_sequence)
    with pspslam.System(sequence, mode="off") as metres, pspslam.System(sequence,
                                                                         mode="off") as raw:
        for f in small_frames[:4]:
            # The synthetic sequence stores depth_factor 5000: metres * 5000 are whole units.
            units = np.rint(np.array(f.depth) * 5000).astype(np.uint16)
            a = metres.track(np.array(f.image), np.array(f.depth), timestamp=f.timestamp)
            b = raw.track(np.array(f.image), units, timestamp=f.timestamp)
            np.testing.assert_array_equal(a.pose, b.pose)


def test_bad_options_raise(small_sequence):
    sequence = pspslam.read_sequence(small_sequence)
    with pytest.raises(ValueError, match=re.escape(
            "mask_margin: must be an integer in [0, 100], got '101'")):
        pspslam.System(sequence, mask_margin=101)
    with pytest.raises(TypeError, match=re.escape("mask_margin: expected an int, got str")):
        pspslam.System(sequence, mask_margin="3")
    with pytest.raises(ValueError, match=re.escape(
            "new_map_after: must be a number in [0, 3600], got '-1.0'")):
        pspslam.System(sequence, new_map_after=-1.0)
    with pytest.raises(ValueError, match=re.escape(
            "mode: must be one of off | semantic | geometry | full | exhaustive | auto, "
            "got 'fast'")):
        pspslam.System(sequence, mode="fast")
    with pytest.raises(TypeError, match="^System: unexpected keyword 'colour'"):
        pspslam.System(sequence, colour=True)
    with pytest.raises(ValueError, match="^localization: needs load_map"):
        pspslam.System(sequence, localization=True)
    with pytest.raises(pspslam.Error, match="config file not found"):
        pspslam.System("no/such/config.yaml")


def test_config_from_a_dict(small_sequence, small_frames):
    yaml = pytest.importorskip("yaml")
    config = yaml.safe_load((small_sequence / "config.yaml").read_text())
    with pspslam.System(config, mode="off") as from_dict, pspslam.System(
            small_sequence / "config.yaml", mode="off") as from_file:
        for f in small_frames[:4]:
            np.testing.assert_array_equal(from_dict.track(f).pose, from_file.track(f).pose)
    del config["camera"]["fx"]
    with pytest.raises(pspslam.Error, match="^config dict: "):
        pspslam.System(config, mode="off")


def test_frames_announced_are_tracked_in_order(small_sequence, small_frames):
    with pspslam.System(pspslam.read_sequence(small_sequence)) as slam:
        slam.announce(small_frames[0])
        slam.announce(small_frames[1])
        with pytest.raises(ValueError, match=re.escape(
                "frame: expected the frame announced first (timestamp "
                f"{small_frames[0].timestamp:f}): announced frames are tracked in the order "
                "announced")):
            slam.track(small_frames[1])
        slam.track(small_frames[0])
        slam.track(small_frames[1])


def test_a_shut_down_system_refuses_frames(small_sequence, small_frames):
    slam = pspslam.System(pspslam.read_sequence(small_sequence), mode="off")
    with slam:
        slam.track(small_frames[0])
    with pytest.raises(ValueError, match="^track: this System has been shut down$"):
        slam.track(small_frames[1])
