"""docs/results.md: one section per experiment, regenerated alone; its tables from results."""
from pspbench import experiment, report


def test_regenerating_one_section_keeps_the_others(tmp_path):
    results = tmp_path / "results.md"
    first = "<!-- begin experiment a -->\n## A\nold\n<!-- end experiment a -->\n"
    second = "<!-- begin experiment b -->\n## B\nkept\n<!-- end experiment b -->\n"
    report.replace_section(results, "a", first)
    report.replace_section(results, "b", second)
    assert results.read_text().startswith(report.HEADER)
    before = results.read_text()
    report.replace_section(results, "a", first.replace("old", "new"))
    after = results.read_text()
    assert after == before.replace("old", "new")
    assert after.count("<!-- begin experiment") == 2


def result(online_m, poses=100):
    """A finished run as the tables read it: one evaluation, 'whole', of the online file."""
    ate = {"rmse": online_m, "poses": poses}
    return {"evaluations": {"whole": {"online": ate, "final": ate}}, "stats": {"frames": 100}}


def test_spread_variant_widens_the_tie_band_and_missing_cells_are_listed(tmp_path):
    path = tmp_path / "panel.toml"
    path.write_text("title = 'Panel'\nbase = 'base'\nspread_variant = 'jitter'\n"
                    "[variants.base]\n[variants.jitter]\n[variants.candidate]\n"
                    "[[cells]]\nname = 'a'\nsynth = { frames = 10 }\n"
                    "[[cells]]\nname = 'b'\ndata = 'b'\n")
    loaded = experiment.load(path)
    runs = {name: report.CellRuns(results=[result(value)], rows=[("a", "whole")])
            for name, value in (("base", 0.010), ("jitter", 0.0112), ("candidate", 0.011))}
    table = {"a": runs, "b": {name: report.CellRuns(missing="b not in DATA") for name in runs}}
    lines = report.tables(loaded, table)
    assert "| a | 10.0 / 10.0 · 100/100 | 11.2 / 11.2 · 100/100 | 11.0 / 11.0 · 100/100 |" in lines
    assert ("| b | missing: b not in DATA | missing: b not in DATA | missing: b not in DATA |"
            in lines)
    # The candidate is 1.0 mm worse, within the 1.2 mm the base moves under the jitter: a tie.
    assert "| candidate | 0 | 0 | 1 | 0 | +1.00 | 1.10 | +1.00 |" in lines
    assert "| a | +1.00 (1.2) tie |" in lines


def keyframe_result(online_m, final_m, keyframes_m, online_at_keyframes_m):
    files = {"online": online_m, "final": final_m, "keyframes": keyframes_m,
             "online_at_keyframes": online_at_keyframes_m}
    evaluation = {name: {"rmse": value, "poses": 10} for name, value in files.items()}
    return {"evaluations": {"whole": evaluation}, "stats": {"frames": 100}}


def test_keyframe_table_holds_keyframes_after_ba_against_the_online_poses_at_their_stamps(
        tmp_path):
    path = tmp_path / "back_end.toml"
    path.write_text("title = 'Back end'\nbase = 'base'\nkeyframe_table = true\n"
                    "[variants.base]\n[variants.candidate]\n"
                    "[[cells]]\nname = 'a'\nsynth = { frames = 10 }\n"
                    "[[cells]]\nname = 'b'\nsynth = { frames = 10 }\n")
    loaded = experiment.load(path)
    assert loaded.keyframe_table
    rows = [("a", "whole")]
    table = {"a": {"base": report.CellRuns(results=[keyframe_result(0.012, 0.010, 0.009, 0.0125)],
                                           rows=rows),
                   "candidate": report.CellRuns(results=[keyframe_result(0.011, 0.012, 0.013,
                                                                         0.011)], rows=rows)},
             "b": {"base": report.CellRuns(missing="no data"),
                   "candidate": report.CellRuns(results=[None], rows=[("b", "whole")])}}
    lines = report.tables(loaded, table)
    assert "| a | 9.0 / 12.5 ✓ · -2.00 | 13.0 / 11.0 ✗ · +1.00 |" in lines
    assert "| b | missing | — |" in lines
    assert "| keyframes closer | 1 of 1 | 0 of 1 |" in lines


def test_online_poses_at_the_keyframe_stamps_are_kept_in_their_own_file(tmp_path):
    from pspbench import jobs
    (tmp_path / "trajectory.txt").write_text(
        "# timestamp tx ty tz qx qy qz qw\n1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n"
        "3.0 2 0 0 0 0 0 1\n")
    (tmp_path / "keyframes.txt").write_text("1.0 0 0 0 0 0 0 1\n3.0 2.1 0 0 0 0 0 1\n")
    jobs._online_at_keyframes(tmp_path)
    assert (tmp_path / "online_at_keyframes.txt").read_text() == (
        "1.0 0 0 0 0 0 0 1\n3.0 2 0 0 0 0 0 1\n")
