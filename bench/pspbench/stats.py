"""The statistics every experiment shares: medians and spread over repeats, and paired
comparisons of a variant against the base, cell by cell.

A cell's spread is how far its runs move when nothing that matters changes: the range of the
base's and the variant's repeats, and, where the experiment names a spread variant (the base
under a meaningless perturbation), that variant's distance from the base. A difference within
the spread is a tie; a win or a loss must be larger than it.
"""
import statistics
from dataclasses import dataclass

# Runs are deterministic unless they run in real time; equal figures must compare equal.
EXACT = 1e-12


@dataclass
class Summary:
    """The repeats of one cell under one variant (values: lower is better; None = no result)."""
    median: float | None
    low: float | None
    high: float | None
    worst: float | None
    runs: int
    failed: int

    @property
    def spread(self):
        return 0.0 if self.median is None else self.high - self.low


def summarise(values):
    measured = [v for v in values if v is not None]
    if not measured:
        return Summary(None, None, None, None, len(values), len(values))
    return Summary(statistics.median(measured), min(measured), max(measured), max(measured),
                   len(values), len(values) - len(measured))


@dataclass
class Comparison:
    """A variant against the base on one cell."""
    delta: float | None  # variant median - base median
    ratio: float | None  # variant median / base median
    spread: float
    verdict: str  # "win", "loss", "tie", "lost" (variant has no result), "gained", "—"


def compare(base, variant, extra_spread=0.0):
    spread = max(base.spread, variant.spread, extra_spread or 0.0)
    if base.median is None and variant.median is None:
        return Comparison(None, None, spread, "—")
    if variant.median is None:
        return Comparison(None, None, spread, "lost")
    if base.median is None:
        return Comparison(None, None, spread, "gained")
    delta = variant.median - base.median
    ratio = variant.median / base.median if base.median > 0 else None
    if delta < -spread - EXACT:
        verdict = "win"
    elif delta > spread + EXACT:
        verdict = "loss"
    else:
        verdict = "tie"
    return Comparison(delta, ratio, spread, verdict)


@dataclass
class Tally:
    """A variant's paired record against the base over all cells."""
    wins: int
    losses: int
    ties: int
    lost: int
    gained: int
    median_delta: float | None
    median_ratio: float | None
    worst_delta: float | None
    compared: int


def tally(comparisons):
    verdicts = [c.verdict for c in comparisons]
    deltas = [c.delta for c in comparisons if c.delta is not None]
    ratios = [c.ratio for c in comparisons if c.ratio is not None]
    return Tally(wins=verdicts.count("win"), losses=verdicts.count("loss"),
                 ties=verdicts.count("tie"), lost=verdicts.count("lost"),
                 gained=verdicts.count("gained"),
                 median_delta=statistics.median(deltas) if deltas else None,
                 median_ratio=statistics.median(ratios) if ratios else None,
                 worst_delta=max(deltas) if deltas else None, compared=len(deltas))


def median_or_none(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None
