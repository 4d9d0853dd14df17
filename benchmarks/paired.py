"""Paired comparison of two strategies over the same draws: how sure is "wins"?

A count of wins says nothing about its own uncertainty; 13 of 24 is a coin toss. Both draw
benchmarks therefore report, per light count, the mean paired difference (plan minus bar) with
a 95 % bootstrap interval and the two-sided sign-test p-value of the win count, and call a
result a win or a loss only when both agree.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.stats import binomtest, bootstrap

#: Significance level of the sign test behind a "win" or a "loss".
ALPHA = 0.05


@dataclass(frozen=True)
class PairedComparison:
    """``plan - bar`` over paired draws (negative: the plan has the lower error)."""

    mean_diff: float
    low: float
    high: float
    wins: int
    ties: int
    draws: int
    sign_p: float

    def verdict(self) -> str:
        """Win or loss only when the mean and the typical draw agree; else a tie.

        The mean alone can be carried by a few bad draws of one side while the other wins no
        more often than a coin toss, so a win needs both the mean's interval below 0 and the
        sign test (p < :data:`ALPHA`) on the same side. When only the mean is sure, the verdict
        says so ("tie (lower mean)" / "tie (higher mean)").
        """
        losses = self.draws - self.wins - self.ties
        sure = self.sign_p < ALPHA
        if self.high < 0:
            return "win" if sure and self.wins > losses else "tie (lower mean)"
        if self.low > 0:
            return "loss" if sure and losses > self.wins else "tie (higher mean)"
        return "tie"

    def cell(self) -> str:
        losses = self.draws - self.wins - self.ties
        return (
            f"{self.mean_diff:+.2f}° [{self.low:+.2f}, {self.high:+.2f}], {self.wins} won, "
            f"{losses} lost, {self.ties} tied of {self.draws}, p = {self.sign_p:.2g}: "
            f"{self.verdict()}"
        )


def compare(plan: ArrayLike, bar: ArrayLike, seed: int = 0) -> PairedComparison:
    """Mean paired difference with a 95 % BCa bootstrap interval, and the sign test."""
    p, b = np.asarray(plan, dtype=np.float64), np.asarray(bar, dtype=np.float64)
    if p.shape != b.shape or p.ndim != 1 or len(p) < 2:
        raise ValueError("paired comparison needs two equal-length 1-D arrays of >= 2 draws")
    diff = p - b
    wins, losses = int(np.sum(diff < 0)), int(np.sum(diff > 0))
    ties = len(diff) - wins - losses
    if np.ptp(diff) <= 1e-9 * max(1.0, float(np.abs(diff).max())):
        # every draw gave the same difference (to rounding): no spread to resample
        low = high = float(diff.mean())
    else:
        ci = bootstrap(
            (diff,), np.mean, confidence_level=0.95, n_resamples=4999, random_state=seed
        ).confidence_interval
        low, high = float(ci.low), float(ci.high)
        if not (np.isfinite(low) and np.isfinite(high)):
            raise ValueError(f"bootstrap interval undefined for differences {diff}")
    sign_p = float(binomtest(wins, wins + losses).pvalue) if wins + losses else 1.0
    return PairedComparison(float(diff.mean()), low, high, wins, ties, len(diff), sign_p)
