"""The QA's consensus of lights (qa_directions.consensus_images) finds the set it always did.

Of its 300 draws, each had measured every image's misfit (two medians over its sampled
pixels) and indexed the sample twice; now a draw that cannot beat the best set so far (no more
images near their lights than that set holds) stops before the misfits, and a draw that can
measures them only on the images the verdict reads (those near their lights, and the drawn
ones for the scale). These tests hold it to the definition it replaced, written out below.
"""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.reconstruct.qa_directions import (
    CONSENSUS_DRAWS,
    CONSENSUS_PICK,
    consensus_images,
)


def _by_definition(stack, lights, usable, agree_deg, dark):  # type: ignore[no-untyped-def]
    n = stack.shape[0]
    canonical = np.lexsort((lights[:, 2], lights[:, 1], lights[:, 0]))
    idx = canonical[usable[canonical]]
    best = np.zeros(n, bool)
    if idx.size < CONSENSUS_PICK + 2:
        return best
    flat = stack.reshape(n, -1)
    rng = np.random.default_rng(0)
    step = max(1, flat.shape[1] // 6000)
    sample = flat[:, ::step].astype(np.float64)
    best_count = 0
    for _ in range(CONSENSUS_DRAWS):
        pick = rng.choice(idx, CONSENSUS_PICK, replace=False)
        lp = lights[pick]
        if np.linalg.cond(lp) > 10:
            continue
        lit = np.all(sample[pick] > dark, axis=0) & np.all(sample[pick] < 1.0, axis=0)
        if lit.sum() < 50:
            continue
        b = np.linalg.pinv(lp) @ sample[pick][:, lit]
        gram = b @ b.T
        if np.linalg.cond(gram) > 1e6:
            continue
        sol = np.linalg.solve(gram, b @ sample[idx][:, lit].T).T
        unit = sol / np.maximum(np.linalg.norm(sol, axis=1, keepdims=True), 1e-12)
        cos = np.sum(unit * lights[idx], axis=1)
        pred = sol @ b
        obs = sample[idx][:, lit]
        misfit = np.median(np.abs(obs - pred), axis=1) / np.maximum(
            np.median(np.abs(pred), axis=1), 1e-12
        )
        drawn = np.isin(idx, pick)
        ok_fit = misfit <= 2.0 * float(np.median(misfit[drawn])) + 0.01
        agree = (cos >= np.cos(np.radians(agree_deg))) & ok_fit
        if agree.sum() > best_count:
            best_count = int(agree.sum())
            best = np.zeros(n, bool)
            best[idx[agree]] = True
    return best


def _sphere_stack(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    az = rng.random(n) * 2 * np.pi
    el = np.radians(15 + 60 * rng.random(n))
    lights = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    y, x = np.mgrid[-1:1:96j, -1:1:96j]
    z = np.sqrt(np.clip(1.2 - x * x - y * y, 0.05, None))
    normals = np.stack([x, y, z], axis=-1)
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    albedo = 0.4 + 0.3 * (np.sin(7 * x) * np.cos(5 * y) > 0)
    stack = np.stack([albedo * np.maximum(normals @ light, 0.0) for light in lights])
    stack += rng.normal(0.0, 0.005, stack.shape)
    return stack.astype(np.float32), lights


@pytest.mark.parametrize("fault", ["none", "two swapped pairs", "half swapped", "moved from 14 on"])
def test_the_consensus_is_the_set_it_always_was(fault: str) -> None:
    stack, lights = _sphere_stack(24, seed=5)
    recorded = lights.copy()
    if fault == "two swapped pairs":
        recorded[[2, 3]] = recorded[[3, 2]]
        recorded[[9, 17]] = recorded[[17, 9]]
    elif fault == "half swapped":
        for i in range(0, 12, 2):
            recorded[[i, i + 1]] = recorded[[i + 1, i]]
    elif fault == "moved from 14 on":
        stack[13:] = np.roll(stack[13:], 3, axis=2)
    usable = np.ones(24, bool)
    usable[5] = False
    got = consensus_images(stack, recorded, usable, 16.0, 0.01)
    want = _by_definition(stack, recorded, usable, 16.0, 0.01)
    np.testing.assert_array_equal(got, want)
    assert want.sum() >= 6  # a set was found: the comparison means something
