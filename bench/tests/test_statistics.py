"""The runner's statistics: medians and spread over repeats, paired verdicts, tallies."""
from pspbench import stats


def test_summary_of_repeats_keeps_failures_apart():
    summary = stats.summarise([0.012, None, 0.010, 0.014])
    assert (summary.median, summary.low, summary.high) == (0.012, 0.010, 0.014)
    assert summary.worst == 0.014
    assert (summary.runs, summary.failed) == (4, 1)
    assert abs(summary.spread - 0.004) < 1e-15
    assert stats.summarise([None]).median is None


def test_a_difference_within_the_spread_is_a_tie():
    base = stats.summarise([0.010, 0.012])
    assert stats.compare(base, stats.summarise([0.0115])).verdict == "tie"
    assert stats.compare(base, stats.summarise([0.0085])).verdict == "win"
    assert stats.compare(base, stats.summarise([0.0135])).verdict == "loss"
    # A spread variant (the base under a meaningless change) widens the tie band.
    assert stats.compare(base, stats.summarise([0.0135]), extra_spread=0.003).verdict == "tie"


def test_deterministic_runs_tie_only_when_equal():
    base = stats.summarise([0.010])
    assert stats.compare(base, stats.summarise([0.010])).verdict == "tie"
    assert stats.compare(base, stats.summarise([0.0100001])).verdict == "loss"


def test_lost_runs_are_counted_not_dropped():
    base = stats.summarise([0.010])
    lost = stats.compare(base, stats.summarise([None]))
    gained = stats.compare(stats.summarise([None]), base)
    assert (lost.verdict, gained.verdict) == ("lost", "gained")
    tally = stats.tally([lost, gained, stats.compare(base, stats.summarise([0.02])),
                         stats.compare(base, stats.summarise([0.005]))])
    assert (tally.wins, tally.losses, tally.ties, tally.lost, tally.gained) == (1, 1, 0, 1, 1)
    assert tally.compared == 2
    assert abs(tally.median_delta - 0.0025) < 1e-12
    assert abs(tally.worst_delta - 0.010) < 1e-12
    assert abs(tally.median_ratio - 1.25) < 1e-12
