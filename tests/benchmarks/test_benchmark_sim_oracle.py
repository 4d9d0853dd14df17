"""The simulator's hindsight oracle and scene-instance benchmarks
(benchmarks.planner_sim_oracle, benchmarks.planner_sim_instances).

The oracle is read as "what a layout could do here", so its search must really minimise the
cost it is given, never return worse than its start, and not stop before every candidate was
tried when it samples them; its cost must be the measured error against the truth.
"""

from __future__ import annotations

import numpy as np

from benchmarks.planner_real_data import hindsight_exchange
from benchmarks.planner_sim_instances import instance_errors
from benchmarks.planner_sim_oracle import fresh_shots, true_error_cost
from benchmarks.tradeoff import SceneData, TradeoffSettings, render_scene_data
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.uniform import select_uniform_leds

DIRS = fibonacci_cap(30, 10.0, 85.0)
QUICK = TradeoffSettings(size_px=32, candidates=60, ground_truth_lights=50, held_out_lights=1)


def _separable(values: np.ndarray):
    return lambda sel: float(np.sum(values[list(sel)]))


def test_exchange_finds_the_cheapest_lights_and_never_worsens_its_start() -> None:
    values = np.random.default_rng(3).uniform(0, 1, len(DIRS))
    start = np.array([0, 1, 2, 3, 4])
    chosen = hindsight_exchange(5, DIRS, _separable(values), start, sweeps=3)
    assert sorted(chosen.tolist()) == sorted(np.argsort(values)[:5].tolist())
    strided = hindsight_exchange(5, DIRS, _separable(values), start, sweeps=2, stride=2)
    assert len(set(strided.tolist())) == 5
    assert _separable(values)(strided) <= _separable(values)(start)


def test_exchange_with_a_stride_does_not_stop_before_every_light_was_tried() -> None:
    """A first sweep over the even lights that finds nothing must not end the search: the
    only better light here is odd."""
    values = np.ones(len(DIRS))
    start = np.array([0, 2, 4, 6])
    values[start] = 0.5
    values[17] = 0.0
    chosen = hindsight_exchange(4, DIRS, _separable(values), start, sweeps=2, stride=2)
    assert 17 in chosen.tolist()


def test_exchange_starts_from_the_homogeneous_layout_by_default() -> None:
    dome = DomeGeometry(DIRS, tuple(map(str, range(len(DIRS)))))
    flat = lambda sel: 0.0  # noqa: E731 — nothing to gain: the start is returned
    np.testing.assert_array_equal(hindsight_exchange(6, DIRS, flat), select_uniform_leds(dome, 6))


def _lambert_scene() -> SceneData:
    rng = np.random.default_rng(0)
    normals = rng.normal([0, 0, 1], 0.2, size=(8, 8, 3))
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    images = np.clip(np.einsum("hwc,kc->khw", normals, DIRS), 0, None)[..., None] * 0.5
    return SceneData(
        name="lambert",
        normals=normals,
        candidate_dirs=DIRS,
        candidate_images=np.repeat(images, 3, axis=-1).astype(np.float32),
        held_dirs=DIRS[:1],
        held_images=np.zeros((1, 8, 8, 3), np.float32),
        preview=np.zeros((8, 8, 3), np.float32),
    )


def test_oracle_cost_is_the_error_against_the_true_normals() -> None:
    data = _lambert_scene()
    cost = true_error_cost(data)
    good = np.arange(0, 30, 5)
    assert cost(good) < 0.5  # exact Lambertian images: photometric stereo recovers the truth
    data.candidate_images[good] = data.candidate_images[good][..., ::-1, :, :]  # flip rows
    assert cost(good) > 5.0


def test_fresh_shots_are_new_noise_on_the_same_lights() -> None:
    data = render_scene_data("tablet", QUICK)
    shots = fresh_shots("tablet", QUICK, data.candidate_dirs, [7, 3, 7])
    assert sorted(shots) == [3, 7]
    for k, img in shots.items():
        first = data.candidate_images[k]
        assert img.shape == first.shape
        assert not np.array_equal(img, first)  # another noise draw ...
        assert np.abs(img - first).mean() < 0.05 * max(first.mean(), 1e-3) + 0.01  # ... same light


def test_instances_are_other_scenes_and_every_strategy_is_scored() -> None:
    one = TradeoffSettings(**{**QUICK.__dict__, "seed": 1})
    two = TradeoffSettings(**{**QUICK.__dict__, "seed": 2})
    a, b = render_scene_data("tilted", one), render_scene_data("tilted", two)
    assert np.degrees(np.arccos(np.clip(np.sum(a.normals * b.normals, -1), -1, 1))).mean() > 5
    err = instance_errors("tilted", one, counts=(6,), draws=2, removed=10)
    labels = {label for _, label in err}
    assert labels == {"uniform 0", "uniform 10", "uniform 20", "uniform 30", "optimal"}
    assert all(len(v) == 2 and np.all(np.isfinite(v)) for v in err.values())


def test_paired_draws_are_the_designs_draws() -> None:
    """The draw benchmarks share this generator; it must give the subsets the explicit loop
    gave (same generator calls, same order), so their committed tables stand."""
    from benchmarks.planner_sim_draws import paired_draws

    cand = fibonacci_cap(40, 3.0, 87.0)
    got = list(paired_draws(cand, (6, 9), 3, 5, np.random.default_rng(7)))
    rng = np.random.default_rng(7)
    want = [(n, np.sort(rng.choice(40, 35, replace=False))) for n in (6, 9) for _ in range(3)]
    assert [n for n, _, _ in got] == [n for n, _ in want]
    for (_, keep, sub), (_, expected) in zip(got, want, strict=True):
        np.testing.assert_array_equal(keep, expected)
        np.testing.assert_array_equal(sub.directions, cand[keep])
        assert sub.names == tuple(f"c{i:03d}" for i in keep)
