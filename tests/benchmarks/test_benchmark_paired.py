"""The paired comparison behind the draw benchmarks' verdicts (benchmarks.paired)."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.paired import compare


def _bar(n: int = 24) -> np.ndarray:
    return np.random.default_rng(1).normal(3.5, 0.6, n)


def test_consistent_small_gain_is_a_win() -> None:
    bar = _bar()
    plan = bar - 0.3 + np.random.default_rng(2).normal(0.0, 0.1, bar.size)
    c = compare(plan, bar)
    assert c.verdict() == "win"
    assert c.high < 0 and c.low < c.mean_diff < c.high
    assert c.wins >= 20 and c.sign_p < 0.01


def test_consistent_loss_is_a_loss() -> None:
    bar = _bar()
    c = compare(bar + 0.5, bar)
    assert c.verdict() == "loss" and c.wins == 0 and c.mean_diff == pytest.approx(0.5)


def test_noise_around_zero_is_a_tie_even_with_more_wins() -> None:
    """13 of 24 with a mean gain smaller than the spread is what the real dome showed at 12."""
    bar = _bar()
    noise = np.random.default_rng(3).normal(0.0, 0.8, bar.size)
    plan = bar + noise - noise.mean() - 0.05
    c = compare(plan, bar)
    assert c.verdict() == "tie" and c.low < 0 < c.high
    assert "tie" in c.cell() and f"{c.wins} won" in c.cell()


def test_identical_strategies_tie_with_p_one() -> None:
    bar = _bar()
    c = compare(bar, bar)
    assert (c.mean_diff, c.ties, c.wins, c.sign_p, c.verdict()) == (0.0, 24, 0, 1.0, "tie")


def test_unpaired_input_is_refused() -> None:
    with pytest.raises(ValueError, match="equal-length"):
        compare([1.0, 2.0, 3.0], [1.0, 2.0])


def test_a_mean_carried_by_a_few_draws_is_not_a_win() -> None:
    """Lower mean (a few disasters of the bar) but a coin toss per draw: the real dome at 12."""
    bar = _bar(48)
    rng = np.random.default_rng(4)
    plan = bar + rng.choice([-0.1, 0.1], bar.size)
    plan[:5] -= 4.0  # the bar had five bad draws
    c = compare(plan, bar)
    assert c.high < 0, "the mean is surely lower"
    assert c.sign_p > 0.05
    assert c.verdict() == "tie (lower mean)"
    assert compare(bar, plan).verdict() == "tie (higher mean)"


def test_more_wins_than_losses_is_not_enough_without_the_sign_test() -> None:
    """22 small wins, 5 large ones and 21 small losses: the mean is sure, the sign test is not."""
    bar = _bar(48)
    diff = np.r_[np.full(22, -0.05), np.full(21, 0.05), np.full(5, -3.0)]
    c = compare(bar + diff, bar)
    assert c.wins > 48 - c.wins - c.ties and c.high < 0 and c.sign_p > 0.05
    assert c.verdict() == "tie (lower mean)"


def test_mean_and_sign_test_on_opposite_sides_is_a_tie() -> None:
    """Loses 40 draws by a little, wins 8 by a lot: lower mean, but the typical draw is worse."""
    bar = _bar(48)
    diff = np.r_[np.full(40, 0.1), np.full(8, -4.0)]
    c = compare(bar + diff, bar)
    assert c.high < 0 and c.sign_p < 0.05
    assert c.verdict() == "tie (lower mean)"
    assert compare(bar - diff, bar).verdict() == "tie (higher mean)"


def test_ties_do_not_count_for_the_sign_test() -> None:
    """5 wins and 43 exact ties: 5 of 5 untied draws is not significant (p = 0.0625)."""
    bar = _bar(48)
    diff = np.r_[np.full(5, -1.0), np.zeros(43)]
    c = compare(bar + diff, bar)
    assert (c.wins, c.ties) == (5, 43) and c.sign_p == pytest.approx(0.0625)
    assert "5 won, 0 lost, 43 tied of 48" in c.cell()
    assert c.verdict() == "tie (lower mean)"
