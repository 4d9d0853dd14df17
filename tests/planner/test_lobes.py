"""The specular lobe's powers by squaring (planner.adaptive_bias.lobes) match ``**``."""

import numpy as np
import pytest

from rti_rig.planner.adaptive_bias import LOBE_EXPONENTS, LOBE_FLOOR, _lobe, lobes


def _reference(c: np.ndarray, e: float) -> np.ndarray:
    with np.errstate(under="ignore"):
        p = np.clip(c, 0.0, 1.0) ** e
    return np.where(p > LOBE_FLOOR, p, 0.0)


@pytest.mark.parametrize(
    "exponents",
    [LOBE_EXPONENTS, (512.0,), (3.0, 6.0, 12.0), (8.0, 4.0, 5.5, 1.0), (2.0, 2.0, 16.0)],
)
def test_powers_match_the_reference(exponents: tuple[float, ...]) -> None:
    rng = np.random.default_rng(1)
    # cosines across the range, the floor's neighbourhood at every exponent, and out-of-range
    c = np.concatenate(
        [
            rng.uniform(0.0, 1.0, 5000),
            [LOBE_FLOOR ** (1.0 / e) * f for e in exponents for f in (0.999, 1.001)],
            [-0.5, 0.0, 1.0, 1.5, 1e-300],
        ]
    )
    got = list(lobes(c, exponents))
    assert len(got) == len(exponents)
    for e, g in zip(exponents, got, strict=True):
        want = _reference(c, e)
        # zero exactly where the reference is, away from the floor's rounding
        near = np.abs(want - LOBE_FLOOR) < 1e-12 * LOBE_FLOOR + 1e-20
        assert ((g > 0) == (want > 0))[~near].all(), e
        np.testing.assert_allclose(g, want, rtol=1e-12, atol=0.0)
        np.testing.assert_allclose(_lobe(c, e), want, rtol=1e-12, atol=0.0)


def test_no_power_falls_into_denormals() -> None:
    c = np.full(1000, 0.05)
    for e, g in zip(LOBE_EXPONENTS, lobes(c, LOBE_EXPONENTS), strict=True):
        assert (g == 0.0).all() if 0.05**e <= LOBE_FLOOR else (g > LOBE_FLOOR).all(), e
