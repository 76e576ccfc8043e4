"""`pspslam run` and pspslam.System take one set of options: every run flag that shapes the System
is a keyword with the same default, range and error, and a run with the same options reports the
same settings from either, deterministic and live alike."""

import json
import re
import subprocess

import pytest

import pspslam

# Flags only a command-line run has: its input, outputs, process-wide settings and viewer. A new
# `pspslam run` flag that shapes the System belongs in session/run_option_table.cpp instead;
# output flags (--export-*, --save-*) and the viewer's (--viewer*) are recognised by their names.
CLI_ONLY = {"--help", "--log-level", "--quiet", "--sequence", "--camera", "--video", "--config",
            "--sensor", "--trajectory-format", "--out", "--max-frames", "--start-frame",
            "--preload", "--priority", "--opencv-threads", "--blackout"}
OUTPUT_FLAG = re.compile(r"^--(export|save|viewer)(-[a-z-]+)?$")
# The occupancy map's own options (--occupancy, --occupancy-resolution, ...) are keywords like any
# other; its scoring against a synthetic truth is the CLI's, and the 2D grid's band
# (--grid-min-height, --grid-max-height, --grid-floor) is System.occupancy_grid()'s arguments.
CLI_ONLY |= {"--occupancy-truth", "--grid-min-height", "--grid-max-height", "--grid-floor"}


def run_flags(cli):
    text = subprocess.run([cli, "run", "--help"], capture_output=True, text=True,
                          check=True).stdout
    return set(re.findall(r"^\s+(?:-\w, ?)?(--[a-z][a-z0-9-]*)", text, re.MULTILINE))


def table():
    return {option["keyword"]: option for option in pspslam.run_options()}


def cli_settings(cli, sequence, out, words):
    subprocess.run([cli, "-q", "run", "--sequence", str(sequence), "--out", str(out),
                    "--max-frames", "3"] + words, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    return json.loads((out / "stats.json").read_text())["settings"]


def python_settings(sequence, keywords):
    with pspslam.System(pspslam.read_sequence(sequence), **keywords) as slam:
        return slam.settings


def test_every_run_flag_is_a_keyword_or_only_the_cli_s(cli):
    flags = {option["flag"] for option in pspslam.run_options() if option["flag"]}
    for flag in sorted(run_flags(cli)):
        if flag in CLI_ONLY or OUTPUT_FLAG.match(flag):
            continue
        assert flag in flags, f"{flag}: neither a System keyword nor one of the CLI's own flags"
    # And every keyword's flag is a flag of the program.
    assert flags <= run_flags(cli)


@pytest.mark.parametrize("live", [[], ["--realtime"]], ids=["deterministic", "realtime"])
def test_default_settings_are_the_same(cli, small_sequence, tmp_path, live):
    from_cli = cli_settings(cli, small_sequence, tmp_path / "out", live)
    from_python = python_settings(small_sequence, {"realtime": bool(live)})
    assert from_cli == from_python
    assert set(from_python) == set(table())
    if live:  # the live defaults, resolved
        assert from_python["local_ba_keyframes"] == "10"
        assert from_python["background_nice"] == "10"
        assert from_python["late_mask_culling"] == "on"


def test_a_live_source_gets_the_camera_s_defaults(small_sequence):
    live = python_settings(small_sequence, {"live": True})
    replay = python_settings(small_sequence, {})
    assert live["local_ba_keyframes"] == "10" and replay["local_ba_keyframes"] == "0"
    assert live["new_map_after"] == "3" and replay["new_map_after"] == "1"
    assert live["background_nice"] == "10" and replay["background_nice"] == "0"


def changed_values(small_sequence):
    """A value other than the default for every option that a 3-frame run can take."""
    data = pspslam.data_dir()
    words = {"mode": ["semantic"], "model": [str(data / "models/pspnet/pspnet.yaml")],
             "realtime": [], "local_mapping": [], "background_nice": ["4"],
             "segment_every": ["2"], "semantic_pace": ["on"],
             "smaller_model": [str(data / "models/pspnet/pspnet_288x192.yaml")],
             "stale_masks": ["flow"], "stale_mask_growth": ["30"], "stale_geometry": ["off"],
             "late_mask_culling": ["off"], "judged_points_first": ["off"],
             "mover_guard": ["on"], "semantic_delay_ms": ["random:1:3"],
             "semantic_delay_seed": ["5"], "semantic_masks": [str(small_sequence / "mask")],
             "mask_margin": ["7"], "keyframe_ratio": ["0.5"], "local_ba_keyframes": ["3"],
             "local_ba_fixed_keyframes": ["2"], "ba_tracking_factors": ["0.25"],
             "due_keyframes": [], "motion_prior": ["2.5", "0.5"],
             "vocabulary": [str(data / "models/vocabulary/orb_k10_l5.pspvoc")],
             "relocalization": [], "new_map_after": ["2.5"], "loop_closing": ["off"],
             "cull_hits": ["4"], "cull_evidence": ["mask"], "occupancy": [],
             "occupancy_resolution": ["0.1"], "occupancy_max_range": ["3"],
             "occupancy_masks": ["off"], "occupancy_clearing": ["off"]}
    keywords = {"mode": "semantic", "model": words["model"][0], "realtime": True,
                "local_mapping": False, "background_nice": 4, "segment_every": 2,
                "semantic_pace": "on", "smaller_model": words["smaller_model"][0],
                "stale_masks": "flow", "stale_mask_growth": 30, "stale_geometry": "off",
                "late_mask_culling": "off", "judged_points_first": "off", "mover_guard": "on",
                "semantic_delay_ms": "random:1:3", "semantic_delay_seed": 5,
                "semantic_masks": words["semantic_masks"][0], "mask_margin": 7,
                "keyframe_ratio": 0.5, "local_ba_keyframes": 3, "local_ba_fixed_keyframes": 2,
                "ba_tracking_factors": 0.25, "due_keyframes": True, "motion_prior": (2.5, 0.5),
                "vocabulary": words["vocabulary"][0], "relocalization": False,
                "new_map_after": 2.5, "loop_closing": "off", "cull_hits": 4,
                "cull_evidence": "mask", "occupancy": True, "occupancy_resolution": 0.1,
                "occupancy_max_range": 3.0, "occupancy_masks": "off", "occupancy_clearing": "off"}
    return words, keywords


def test_the_same_options_give_the_same_settings(cli, small_sequence, tmp_path):
    words, keywords = changed_values(small_sequence)
    options = table()
    # Every option but those a run without a saved map cannot take, and `live` (--camera).
    assert set(words) == set(options) - {"load_map", "localization", "live"}
    cli_words = []
    for keyword, values in words.items():
        cli_words += [options[keyword]["flag"]] + values
    from_cli = cli_settings(cli, small_sequence, tmp_path / "out", cli_words)
    from_python = python_settings(small_sequence, keywords)
    assert from_cli == from_python
    defaults = python_settings(small_sequence, {})
    # Each value reached the System (the shipped files named are the defaults themselves).
    for keyword in set(words) - {"model", "smaller_model", "vocabulary"}:
        assert from_python[keyword] != defaults[keyword], keyword


def bad_values():
    """(keyword, the same bad value as typed and as Python's) for every checked option."""
    for option in pspslam.run_options():
        kind = option["kind"]
        if not option["flag"]:
            continue
        if kind == "integer":
            yield option, [str(int(option["high"]) + 1)], int(option["high"]) + 1
        elif kind == "real":
            yield option, [repr(option["high"] + 1.5)], option["high"] + 1.5
        elif kind == "real_pair":
            yield option, ["1.0", repr(option["high"] + 1.5)], (1.0, option["high"] + 1.5)
        elif kind == "choice":
            yield option, ["bogus"], "bogus"
        elif kind == "text":
            yield option, ["bogus"], "bogus"
        elif kind == "path" and option["keyword"] in ("smaller_model", "load_map",
                                                      "semantic_masks"):
            yield option, ["no/such/path"], "no/such/path"


@pytest.mark.parametrize("option,typed,value", list(bad_values()),
                         ids=lambda v: v["keyword"] if isinstance(v, dict) else None)
def test_a_bad_value_is_the_same_error(cli, small_sequence, tmp_path, option, typed, value):
    run = subprocess.run([cli, "run", "--sequence", str(small_sequence), "--out",
                          str(tmp_path / "out"), option["flag"]] + typed,
                         capture_output=True, text=True)
    assert run.returncode == 2
    match = re.search(r"error: pspslam run: (--[\w-]+): (.*) \(see ", run.stderr)
    assert match, run.stderr
    assert match.group(1) == option["flag"]
    with pytest.raises(ValueError) as raised:
        pspslam.System(pspslam.read_sequence(small_sequence), **{option["keyword"]: value})
    assert str(raised.value) == f"{option['keyword']}: {match.group(2)}"


def test_options_that_go_together_are_told_alike(cli, small_sequence, tmp_path):
    run = subprocess.run([cli, "run", "--sequence", str(small_sequence), "--out",
                          str(tmp_path / "out"), "--localization"], capture_output=True, text=True)
    assert run.returncode == 2
    assert "--localization: needs --load-map (a map to localise in)" in run.stderr
    with pytest.raises(ValueError, match=r"^localization: needs load_map \(a map to localise "
                                         r"in\)$"):
        pspslam.System(pspslam.read_sequence(small_sequence), localization=True)
    run = subprocess.run([cli, "run", "--sequence", str(small_sequence), "--out",
                          str(tmp_path / "out2"), "--occupancy-resolution", "0.5",
                          "--occupancy-max-range", "0.4"], capture_output=True, text=True)
    assert run.returncode == 2
    assert "--occupancy-max-range: must exceed --occupancy-resolution" in run.stderr
    with pytest.raises(ValueError, match=r"^occupancy_max_range: must exceed "
                                         r"occupancy_resolution$"):
        pspslam.System(pspslam.read_sequence(small_sequence), occupancy_resolution=0.5,
                       occupancy_max_range=0.4)
