"""The relighting design score (planner/adaptive_relight.py): it measures what the benchmarks
measure (relighting PSNR of the basis fitted on the design, on the lights left out), it can
prefer another floor than the normals score on the same object, the design choice follows the
objective asked for, and its hysteresis keeps the current design within the margin."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.metrics import relight_psnr
from rti_rig.app.usecases.adaptive import AdaptiveChooser, relight_fit, robust_fit
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.planner.adaptive import (
    DESIGN_FLOORS,
    SurfaceState,
    choose_in_design,
    homogeneous_completion,
)
from rti_rig.planner.adaptive_bias import ObjectModel, simulate_designs
from rti_rig.planner.adaptive_relight import (
    RELIGHT_MARGIN_DB,
    held_out,
    mean_psnr_db,
    pick_floor,
    relight_basis,
    simulate_relight_designs,
)
from rti_rig.reconstruct import fit_hsh, fit_ptm

CANDIDATES = fibonacci_cap(120, 0.0, 90.0)


def _normals(p: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n = rng.normal(size=(p, 3)) * [0.3, 0.3, 1.0]
    n[:, 2] = np.abs(n[:, 2]) + 0.6
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def grazing_shadow_object(seed: int = 0, p: int = 400, horizon_deg: float = 12.0) -> ObjectModel:
    """A matte relief (albedo 0.5, 0.5 % noise) whose every pixel is cast-shadowed from every
    light below ``horizon_deg``, whatever its azimuth (a horizon seen in 12 azimuths)."""
    s = 12
    return ObjectModel(
        normals=_normals(p, seed),
        albedo=np.full(p, 0.5),
        spec_strength=0.0,
        spec_exponent=8.0,
        noise=0.005,
        shadow_el=np.full((p, s), horizon_deg),
        shadow_az=np.tile(np.arange(s) * 30.0, (p, 1)),
        lights=np.zeros((0, 3)),
        shadowed=np.zeros((p, 0), dtype=bool),
    )


def _designs(n_total: int, used: np.ndarray | None = None) -> dict[float, np.ndarray]:
    used = np.zeros((0, 3)) if used is None else used
    avail = np.ones(len(CANDIDATES), dtype=bool)
    out = {f: homogeneous_completion(CANDIDATES, avail, used, n_total, f) for f in DESIGN_FLOORS}
    return {f: c for f, c in out.items() if c is not None}


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_relight_score_prefers_another_floor_than_the_normals_score(seed: int) -> None:
    """Grazing lights are all in shadow on this object: for normals the 10° layout's extra
    spread wins (its few shadowed lights are discarded by the robust fit), while relighting
    prefers 20° — fitting a smooth basis through the shadow edge spoils it everywhere else."""
    model = grazing_shadow_object(seed)
    designs = _designs(9)
    avail = np.ones(len(CANDIDATES), dtype=bool)
    full = [CANDIDATES[c] for c in designs.values()]
    normals = dict(zip(designs, simulate_designs(model, full, robust_fit), strict=True))
    held = [held_out(CANDIDATES, avail, c) for c in designs.values()]
    psnr = dict(
        zip(
            designs,
            simulate_relight_designs(model, full, held, relight_fit, relight_basis(9)),
            strict=True,
        )
    )
    assert min(normals, key=normals.__getitem__) == 10.0
    assert normals[20.0] > 1.05 * normals[10.0]
    assert max(psnr, key=psnr.__getitem__) == 20.0
    assert psnr[20.0] > psnr[10.0] + 0.2 and psnr[20.0] > psnr[0.0] + 3.0
    # deterministic: a decision is a function of the images (resume repeats it)
    again = simulate_relight_designs(
        grazing_shadow_object(seed), full, held, relight_fit, relight_basis(9)
    )
    assert again == list(psnr.values())


def _state_of(model: ObjectModel) -> SurfaceState:
    """A state whose object model is ``model``, before any light is captured (the designs are
    then the homogeneous layouts themselves, as in the test above); its observations are
    placeholders: the model is what the design scores simulate."""
    p = len(model.normals)
    state = SurfaceState(
        model.normals,
        model.albedo,
        np.full(p, model.noise),
        np.zeros((p, 0), dtype=bool),
        np.zeros((0, 3)),
        obs=np.zeros((0, p), dtype=np.float32),
        valid=np.ones(p, dtype=bool),
    )
    state.cache["object_model"] = model
    return state


def test_the_design_follows_the_objective_asked_for(monkeypatch: pytest.MonkeyPatch) -> None:
    """From the 0° layout (as a session whose current design it is), the normals objective
    moves to 10° and the relight objective to 20° (both beyond their margins), each recording
    its own scores. Among the floors: the fitted designs (``FITTED_DESIGN`` for normals,
    ``RELIGHT_FITTED_DESIGN`` for relight, tested in test_adaptive_relight_design.py) are left
    out here, or they would be the objectives' picks."""
    import rti_rig.planner.adaptive as adaptive
    import rti_rig.planner.adaptive_relight as adaptive_relight

    monkeypatch.setattr(adaptive, "FITTED_DESIGN", False)
    monkeypatch.setattr(adaptive_relight, "RELIGHT_FITTED_DESIGN", False)
    avail = np.ones(len(CANDIDATES), dtype=bool)
    kw = dict(fit=robust_fit, default_floor=0.0)
    d_n = choose_in_design(_state_of(grazing_shadow_object(0)), CANDIDATES, avail, 9, **kw)
    d_r = choose_in_design(
        _state_of(grazing_shadow_object(0)),
        CANDIDATES,
        avail,
        9,
        objective="relight",
        relight=relight_fit,
        **kw,
    )
    assert d_n.design_floor == 10.0 and d_r.design_floor == 20.0
    ev_n, ev_r = d_n.evidence(), d_r.evidence()
    assert ev_n["design_objective"] == "normals" and "design_psnr_db" not in ev_n
    assert set(ev_n["design_error_deg"]) == {"0", "10", "20", "30"}
    assert ev_r["design_objective"] == "relight" and "design_error_deg" not in ev_r
    psnr = ev_r["design_psnr_db"]
    assert max(psnr, key=psnr.__getitem__) == "20"
    # the light chosen is one of the chosen design's
    assert d_r.candidate in set(_designs(9)[20.0].tolist())
    assert d_n.candidate in set(_designs(9)[10.0].tolist())


def test_the_relight_objective_needs_its_simulation() -> None:
    state = _state_of(grazing_shadow_object(0))
    avail = np.ones(len(CANDIDATES), dtype=bool)
    with pytest.raises(ValueError, match="give fit and relight"):
        choose_in_design(state, CANDIDATES, avail, 9, fit=robust_fit, objective="relight")
    with pytest.raises(ValueError, match="unknown objective"):
        choose_in_design(state, CANDIDATES, avail, 9, objective="psnr")
    with pytest.raises(ValueError):  # light by light there is no design to choose
        AdaptiveChooser(CANDIDATES, [0, 1, 2, 3], 9, objective="relight")


def test_the_score_is_the_benchmarks_relighting_psnr() -> None:
    """``mean_psnr_db`` of ``relight_fit`` equals ``benchmarks.metrics.relight_psnr`` of the
    model the benchmarks fit (``fit_ptm``/``fit_hsh`` on the images), on the held-out images."""
    rng = np.random.default_rng(3)
    h, w = 6, 7
    n = _normals(h * w, 3)
    lights = fibonacci_cap(40, 0.0, 90.0)
    images = (0.5 * np.maximum(n @ lights.T, 0.0)).T + rng.normal(0, 0.01, (40, h * w))
    images = np.clip(images, 0.0, None).astype(np.float32)
    fit_idx, held_idx = np.arange(0, 40, 3), np.setdiff1d(np.arange(40), np.arange(0, 40, 3))
    for basis, fit in (("ptm", fit_ptm), ("hsh2", lambda im, lt: fit_hsh(im, lt, 2))):
        model = fit(images[fit_idx].reshape(-1, h, w), lights[fit_idx])
        expected = relight_psnr(model, images[held_idx].reshape(-1, h, w), lights[held_idx], 1.0)
        relit = relight_fit(images[fit_idx], lights[fit_idx], lights[held_idx], basis)
        assert mean_psnr_db(relit, images[held_idx], 0.0) == pytest.approx(expected, abs=1e-3)
    # the photograph's noise adds to the squared error of every held-out light
    ref = np.zeros((2, 5))
    relit = np.full((2, 5), 0.1)
    assert mean_psnr_db(relit, ref, 0.0) == pytest.approx(20.0)
    assert mean_psnr_db(relit, ref, 0.1) == pytest.approx(20.0 - 10 * np.log10(2.0))


def test_pick_floor_keeps_the_current_design_within_the_margin() -> None:
    scores = {0.0: 30.0, 10.0: 30.0 + RELIGHT_MARGIN_DB * 0.9, 20.0: 29.0}
    assert pick_floor(scores, 0.0) == 0.0  # within the margin: kept
    assert pick_floor(scores, 20.0) == 10.0  # beyond it: the best
    assert pick_floor(scores, 0.0, margin_db=0.0) == 10.0
    assert pick_floor({0.0: 30.0, 10.0: 30.0, 20.0: 30.0}, 10.0, margin_db=0.0) == 10.0


def test_every_design_is_judged_on_the_same_lights(monkeypatch: pytest.MonkeyPatch) -> None:
    """The held-out lights are those still available that none of the designs takes, the same
    for all (as the benchmarks compare layouts); where the designs take every available light,
    each design's own; ``SHARED_HELD_OUT = False`` gives each its own."""
    import rti_rig.planner.adaptive_relight as adaptive_relight

    avail = np.ones(len(CANDIDATES), dtype=bool)
    avail[[0, 1, 2]] = False  # shot already
    designs = [np.array([5, 6, 7]), np.array([7, 8, 9, 10])]
    held, shared = adaptive_relight.shared_held_out(CANDIDATES, avail, designs)
    expected = np.setdiff1d(np.arange(len(CANDIDATES)), [0, 1, 2, 5, 6, 7, 8, 9, 10])
    assert len(held) == 2 and shared
    for h in held:
        assert np.array_equal(h, CANDIDATES[expected])
    few = np.zeros(len(CANDIDATES), dtype=bool)
    few[[5, 6, 7, 8]] = True  # the designs take every light left: each its own
    own, shared = adaptive_relight.shared_held_out(
        CANDIDATES, few, [np.array([5, 6]), np.array([7, 8])]
    )
    assert not shared
    assert np.array_equal(own[0], CANDIDATES[[7, 8]]) and np.array_equal(own[1], CANDIDATES[[5, 6]])
    monkeypatch.setattr(adaptive_relight, "SHARED_HELD_OUT", False)
    apart, shared = adaptive_relight.shared_held_out(CANDIDATES, avail, designs)
    assert not shared
    assert np.array_equal(apart[0], held_out(CANDIDATES, avail, designs[0]))


def test_a_lobe_no_camera_could_show_is_relit_as_a_camera_records_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A lobe fitted on few images can be sharp and very strong (a matte tilted plane after its
    4 starting images: ks 9e4 at exponent 512). The relight score simulates what a camera
    records — nothing above its top code — so every design's simulated relighting stays a
    relighting score; unclipped, the designs read far below 0 dB."""
    import dataclasses

    import rti_rig.planner.adaptive_relight as adaptive_relight
    from rti_rig.planner.adaptive_bias import render

    model = dataclasses.replace(grazing_shadow_object(0), spec_strength=9.0e4, spec_exponent=512.0)
    designs = _designs(12)
    full = [CANDIDATES[c] for c in designs.values()]
    avail = np.ones(len(CANDIDATES), dtype=bool)
    held = [held_out(CANDIDATES, avail, c) for c in designs.values()]
    pix = np.arange(len(model.normals))
    assert render(model, CANDIDATES, pix).max() > 100.0  # the model's own rendering
    assert adaptive_relight.saturated(render(model, CANDIDATES, pix)).max() == 1.0
    assert adaptive_relight.SATURATION == 1.0
    brightest: list[float] = []

    def relight(obs, lights, ho, basis):  # type: ignore[no-untyped-def]
        brightest.append(float(obs.max()))  # the simulated photographs, as a camera clips
        return relight_fit(obs, lights, ho, basis)

    clipped = simulate_relight_designs(model, full, held, relight, "ptm")
    assert min(clipped) > 10.0 and max(brightest) <= 1.0
    monkeypatch.setattr(adaptive_relight, "SATURATION", None)
    assert min(simulate_relight_designs(model, full, held, relight_fit, "ptm")) < 0.0


@pytest.mark.parametrize("objective", ["normals", "relight"])
def test_designs_that_are_the_same_lights_are_simulated_and_listed_once(
    objective: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """On a dome whose lowest lights are at 10° (the shipped simulated dome's are), the
    designs above 0° and 10° are the same lights: each decision simulated that layout twice
    and listed it twice in the evidence with equal scores ("0" and "10"). Each distinct layout
    is now simulated once and listed once, named by the floor all its lights lie above; the
    choice is the one the duplicate-scoring build made (the same scores, the same ties)."""
    import rti_rig.planner.adaptive as adaptive
    import rti_rig.planner.adaptive_relight as adaptive_relight

    monkeypatch.setattr(adaptive, "FITTED_DESIGN", False)
    monkeypatch.setattr(adaptive_relight, "RELIGHT_FITTED_DESIGN", False)
    cand = fibonacci_cap(120, 10.0, 90.0)  # no light below 10°
    avail = np.ones(len(cand), dtype=bool)
    comps = {f: homogeneous_completion(cand, avail, np.zeros((0, 3)), 9, f) for f in DESIGN_FLOORS}
    assert np.array_equal(comps[0.0], comps[10.0]) and not np.array_equal(comps[10], comps[20])
    seen: list[int] = []
    inner = (
        adaptive.simulate_designs if objective == "normals" else adaptive.simulate_relight_designs
    )
    name = "simulate_designs" if objective == "normals" else "simulate_relight_designs"

    def counted(model, designs, *args, **kwargs):  # type: ignore[no-untyped-def]
        seen.append(len(designs))
        return inner(model, designs, *args, **kwargs)

    monkeypatch.setattr(adaptive, name, counted)
    kw = dict(fit=robust_fit, default_floor=0.0, objective=objective, relight=relight_fit)
    d = choose_in_design(_state_of(grazing_shadow_object(0)), cand, avail, 9, **kw)
    assert seen == [3]  # 0°/10° (one layout), 20°, 30°
    ev = d.evidence()
    scores = ev["design_error_deg" if objective == "normals" else "design_psnr_db"]
    assert set(scores) == {"10", "20", "30"}
    assert "0" not in scores
    if d.design_floor in (0.0, 10.0):
        assert ev["design_floor_deg"] == 10.0
        assert "above 10° (the designs above 0° and 10° are this one layout)" in d.reason
    # the duplicate-scoring build's choice: every design simulated as it was
    monkeypatch.setattr(adaptive, name, inner)
    monkeypatch.setattr(
        adaptive,
        "_scored_once",
        lambda ds, score: dict(zip(ds, score(list(ds)), strict=True)),
    )
    old = choose_in_design(_state_of(grazing_shadow_object(0)), cand, avail, 9, **kw)
    assert (old.candidate, old.design_floor) == (d.candidate, d.design_floor)
