"""docs/results.md: one section per experiment; regenerating one leaves the others alone."""
from pspbench import report


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
