"""The adaptive decision's fast paths give what their plain expressions give, bit for bit: a
decision is a function of the images, so a speed-up must not move it."""

from __future__ import annotations

import numpy as np

from rti_rig.core.geometry import fibonacci_cap
from rti_rig.planner.adaptive_bias import (
    MARCH_STEPS,
    SOFT_PX,
    _unit_noise,
    light_noise,
    soft_visibility,
)


def _plain_soft_visibility(height, rows, cols, lights):  # type: ignore[no-untyped-def]
    """The march written as plain expressions (the code before the speed-up)."""
    h, w = height.shape
    d = np.asarray(lights, dtype=np.float64)
    horiz = np.hypot(d[:, 0], d[:, 1])
    safe = np.maximum(horiz, 1e-9)
    sx, sy, rise = (
        (d[:, 0] / safe).astype(np.float32),
        (d[:, 1] / safe).astype(np.float32),
        (d[:, 2] / safe).astype(np.float32),
    )
    t = np.arange(1, MARCH_STEPS + 1, dtype=np.float32)
    height = np.asarray(height, dtype=np.float32)
    h0 = height[rows, cols]
    vis = np.ones((len(rows), len(d)))
    todo = np.flatnonzero(
        (horiz >= 1e-6) & (float(height.max()) - float(h0.min()) > rise - SOFT_PX)
    )
    if todo.size == 0:
        return vis
    cc = cols[:, None, None] + t[None, :, None] * sx[todo][None, None, :]
    rr = rows[:, None, None] - t[None, :, None] * sy[todo][None, None, :]
    inside = (cc >= 0) & (cc <= w - 1) & (rr >= 0) & (rr <= h - 1)
    ci = np.clip(np.rint(cc).astype(np.intp), 0, w - 1)
    ri = np.clip(np.rint(rr).astype(np.intp), 0, h - 1)
    ray = h0[:, None, None] + t[None, :, None] * rise[todo][None, None, :]
    excess = np.where(inside, height[ri, ci] - ray, -np.inf).max(axis=1)
    vis[:, todo] = np.clip(1.0 - excess / SOFT_PX, 0.0, 1.0)
    return vis


def test_soft_visibility_is_the_plain_march_bit_for_bit() -> None:
    rng = np.random.default_rng(0)
    seen = []
    for trial in range(12):
        h, w = int(rng.integers(20, 120)), int(rng.integers(20, 140))
        height = rng.normal(size=(h, w)).cumsum(0).cumsum(1) * 0.01 * rng.uniform(0.2, 4.0)
        p = int(rng.integers(1, 400))
        rows, cols = rng.integers(0, h, p), rng.integers(0, w, p)
        lights = fibonacci_cap(int(rng.integers(1, 200)), float(rng.uniform(0.0, 40.0)))
        if trial % 3 == 0:
            lights = np.vstack([lights, [0.0, 0.0, 1.0]])  # the zenith: never blocked
        got = soft_visibility(height, rows, cols, lights)
        seen.append(got)
        assert np.array_equal(got, _plain_soft_visibility(height, rows, cols, lights)), trial
    values = np.concatenate([v.ravel() for v in seen])
    # the cases test something: shadowed, lit and partly lit steps all occur
    assert (values == 0).any() and (values == 1).any() and ((values > 0) & (values < 1)).any()


def test_light_noise_is_each_lights_own_draw_whatever_was_asked_before() -> None:
    lights = fibonacci_cap(30, 10.0)
    first = light_noise(lights[:20], 2, 50, 0.01, 7)
    again = light_noise(lights[10:], 2, 50, 0.03, 7)  # some lights kept, another sigma
    for j, v in enumerate(lights):
        seed = [7, *np.round(v * 1e6).astype(np.int64) % 2**31]
        if j < 20:
            want = np.random.default_rng(seed).normal(0.0, 0.01, (2, 50))
            assert np.array_equal(first[:, j], want)
        if j >= 10:
            want = np.random.default_rng(seed).normal(0.0, 0.03, (2, 50))
            assert np.array_equal(again[:, j - 10], want)
    # the kept draws cannot be written through: cached read-only, never handed out
    key = tuple(int(k) for k in np.round(lights[0] * 1e6).astype(np.int64) % 2**31)
    assert not _unit_noise(7, key, 2, 50).flags.writeable
    assert not np.shares_memory(first, _unit_noise(7, key, 2, 50))
