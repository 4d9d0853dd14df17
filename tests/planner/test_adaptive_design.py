"""The adaptive chooser with N known (planner/adaptive.py): homogeneous designs, the fall-back
to the homogeneous layout, the keep model that lowers a light's worth where the fit discards
what it sees, and the gloss-aware estimate."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import rti_rig.planner.adaptive as adaptive
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.adaptive import (
    SurfaceState,
    choose_in_design,
    design_error_deg,
    discarded_fraction,
    estimate_error_deg,
    estimate_factor,
    homogeneous_completion,
    predicted_weight,
    start_subset,
)
from rti_rig.planner.uniform import select_uniform_leds

sys.path.insert(0, str(Path(__file__).resolve().parent))
from adaptive_states import state_for


def dome(n: int = 120) -> DomeGeometry:
    dirs = fibonacci_cap(n, 3.0)
    return DomeGeometry(dirs, tuple(f"l{i}" for i in range(n)))


@pytest.mark.parametrize("floor", [0.0, 10.0, 20.0, 30.0])
def test_a_completion_of_nothing_is_the_homogeneous_layout(floor: float) -> None:
    g = dome()
    got = homogeneous_completion(g.directions, np.ones(g.count, bool), np.zeros((0, 3)), 12, floor)
    assert got is not None
    assert sorted(got.tolist()) == sorted(select_uniform_leds(g, 12, floor).tolist())


def test_the_start_is_part_of_the_layout_and_the_default_design_completes_it() -> None:
    """From start_subset's start, the default floor's design is the homogeneous layout itself:
    the fall-back loses nothing to it."""
    g = dome()
    full = select_uniform_leds(g, 12, 10.0)
    start = [int(full[i]) for i in start_subset(g.directions[full], 4)]
    assert len(set(start)) == 4 and set(start) <= set(full.tolist())
    available = np.ones(g.count, bool)
    available[start] = False
    rest = homogeneous_completion(g.directions, available, g.directions[start], 12, 10.0)
    assert rest is not None
    assert sorted([*start, *rest.tolist()]) == sorted(full.tolist())


@pytest.mark.parametrize("n", [6, 9, 12, 18])
def test_a_relight_start_takes_no_light_below_its_floor(n: int) -> None:
    """With --objective relight the 4 starting lights (shot before anything is known) are none
    below START_FLOOR_DEG, although the default layout (10°) has lights there; the normals
    objective's start is matched among all the layout's lights and, on this dome, takes one.
    Up to format 8 both did: the 16° light of the relight start was in every design the
    session could complete, so the 20° and 30° layouts were out of reach."""
    g = DomeGeometry(fibonacci_cap(240, 0.0), tuple(f"l{i}" for i in range(240)))
    full = select_uniform_leds(g, n, 10.0)
    layout = g.directions[full]
    el = np.degrees(np.arcsin(layout[:, 2]))
    assert el.min() < adaptive.START_FLOOR_DEG  # the layout has low lights
    start = start_subset(layout, 4, objective="relight")
    assert len(set(start)) == 4 and el[start].min() >= adaptive.START_FLOOR_DEG
    # still spread over the dome (a robust photometric stereo start): no two within 30°
    angles = np.degrees(np.arccos(np.clip(layout[start] @ layout[start].T, -1.0, 1.0)))
    assert angles[~np.eye(4, dtype=bool)].min() > 30.0
    normals = start_subset(layout, 4, objective="normals")
    assert len(set(normals)) == 4 and el[normals].min() < adaptive.START_FLOOR_DEG
    assert start_subset(layout, 4, objective="normals", above_floor=True) == start


def test_a_layout_with_too_few_lights_above_the_floor_starts_with_its_highest() -> None:
    layout = fibonacci_cap(8, 0.0, 25.0)  # at most a few above 20°
    el = np.degrees(np.arcsin(layout[:, 2]))
    assert (el >= adaptive.START_FLOOR_DEG).sum() < 4
    assert start_subset(layout, 4, objective="relight") == sorted(np.argsort(-el)[:4].tolist())


def test_it_falls_back_to_the_default_design_unless_another_is_clearly_better() -> None:
    g = dome()
    full = select_uniform_leds(g, 9, 10.0)
    start = [int(full[i]) for i in start_subset(g.directions[full], 4)]
    normals = fibonacci_cap(200, 60.0)  # a gently curved, matte surface
    st = state_for(normals, g.directions[start])
    available = np.ones(g.count, bool)
    available[start] = False
    scores = {
        f: design_error_deg(
            st,
            g.directions[homogeneous_completion(g.directions, available, st.lights, 9, f)],
        )
        for f in (0.0, 10.0, 20.0, 30.0)
    }
    best = min(scores, key=scores.get)
    d = choose_in_design(st, g.directions, available, 9, default_floor=10.0, margin=10.0)
    assert d.candidate in full and "above 10°" in d.reason  # huge margin: always the default
    d = choose_in_design(st, g.directions, available, 9, default_floor=10.0, margin=0.0)
    assert f"above {best:g}°" in d.reason  # no margin: the best predicted design
    chosen = homogeneous_completion(g.directions, available, st.lights, 9, best)
    assert d.candidate in chosen.tolist()


def test_the_keep_model_lowers_a_light_where_the_fit_discarded_its_kind() -> None:
    """A glossy object: the fit discarded every observation near the mirror direction. A
    candidate there is worth less than before; one far from it is not."""
    normals = np.tile([0.0, 0.0, 1.0], (300, 1))
    lights = fibonacci_cap(12, 20.0)
    st = state_for(normals, lights)
    near_mirror = lights[:, 2] > np.cos(np.radians(20))  # half-way vector within 10° of n
    assert near_mirror.any() and not near_mirror.all()
    glossy = SurfaceState(
        st.normals, st.albedo, st.noise, st.lit & ~near_mirror[None, :], st.lights
    )
    cands = np.array([[0.0, 0.0, 1.0], [np.cos(np.radians(35)), 0.0, np.sin(np.radians(35))]])
    matte_w = predicted_weight(st, cands)
    glossy_w = predicted_weight(glossy, cands)
    assert np.allclose(matte_w, 1.0)
    assert glossy_w[:, 0].max() < 0.6  # the zenith light would likely be discarded again
    assert np.allclose(glossy_w[:, 1], 1.0)  # an oblique light is still worth a light
    assert discarded_fraction(st) == 0.0
    assert discarded_fraction(glossy) == pytest.approx(near_mirror.mean())


def test_the_estimate_grows_with_what_the_fit_discarded(monkeypatch: pytest.MonkeyPatch) -> None:
    normals = fibonacci_cap(100, 50.0)
    lights = fibonacci_cap(10, 20.0)
    st = state_for(normals, lights)
    lit = st.lit.copy()
    lit[:, :3] = False
    rough = SurfaceState(st.normals, st.albedo, st.noise, lit, st.lights)
    monkeypatch.setattr(adaptive, "DISCARD_SLOPE", 0.0)
    assert estimate_factor(rough, 0.8) == pytest.approx(0.8)
    monkeypatch.setattr(adaptive, "DISCARD_SLOPE", 1.5)
    d = discarded_fraction(rough)
    assert 0.2 < d < 0.4
    assert estimate_factor(rough, 0.8) == pytest.approx(0.8 * np.exp(1.5 * d))
    assert estimate_factor(st, 0.8) == pytest.approx(0.8)
    assert estimate_error_deg(rough, 0.8) > estimate_error_deg(st, 0.8)


def test_a_fit_without_observations_to_model_falls_back_to_the_bound() -> None:
    """``fit`` given but the state carries no observations (no object model can be fitted):
    the designs are scored by the bound, as without ``fit`` — it raised a NameError."""
    g = dome()
    full = select_uniform_leds(g, 9, 10.0)
    start = [int(full[i]) for i in start_subset(g.directions[full], 4)]
    st = state_for(fibonacci_cap(200, 60.0), g.directions[start])
    assert st.obs is None
    available = np.ones(g.count, bool)
    available[start] = False

    def never(*_args, **_kwargs):  # type: ignore[no-untyped-def]
        raise AssertionError("no object model: nothing to simulate")

    with_fit = choose_in_design(st, g.directions, available, 9, fit=never)
    without = choose_in_design(st, g.directions, available, 9)
    assert with_fit.candidate == without.candidate and with_fit.reason == without.reason


def test_within_a_band_each_design_is_named_by_the_floor_the_band_applied() -> None:
    """Among a 20°–45° band's lights the designs above 0°, 10° and 20° are one layout: the
    evidence had named it "above 10°" (the default floor), claiming lights below the band were
    open to it. It names the floor the band applied, the ceiling, and the one layout once —
    and the choice is the same as without the band's words (a resume repeats it)."""
    g = dome()
    el = np.degrees(np.arcsin(g.directions[:, 2]))
    cand = g.directions[(el >= 20.0) & (el <= 45.0)]  # what adaptive_plan keeps of the band
    band = DomeGeometry(cand, tuple(f"b{i}" for i in range(len(cand))))
    full = select_uniform_leds(band, 9, 10.0)
    start = [int(full[i]) for i in start_subset(cand[full], 4)]
    st = state_for(fibonacci_cap(200, 60.0), cand[start])
    available = np.ones(len(cand), bool)
    available[start] = False
    for margin in (10.0, 0.0):  # the default design kept; the best one taken
        plain = choose_in_design(st, cand, available, 9, default_floor=10.0, margin=margin)
        named = choose_in_design(
            st, cand, available, 9, default_floor=10.0, margin=margin, band=(20.0, 45.0)
        )
        assert (named.candidate, named.design_floor) == (plain.candidate, plain.design_floor)
        # without the band's words the same lights are still one layout (their designs are
        # the same lights: :func:`_merged_floors`), named by its highest floor
        assert set(plain.evidence()["design_error_deg"]) == {"20", "30"}
        ev = named.evidence()
        assert set(ev["design_error_deg"]) == {"20", "30"}  # one entry per layout
        assert ev["design_floor_deg"] == max(plain.design_floor, 20.0)
        assert plain.evidence()["design_floor_deg"] == ev["design_floor_deg"]
        assert ev["design_ceiling_deg"] == 45.0
        assert ev["design_error_deg"][f"{ev['design_floor_deg']:g}"] == pytest.approx(
            plain.evidence()["design_error_deg"][f"{plain.evidence()['design_floor_deg']:g}"]
        )
        assert f"between {ev['design_floor_deg']:g}° and 45°" in named.reason
        assert "by floor, each up to the 45° ceiling" in named.reason
        assert named.reason.startswith(
            f"homogeneous design of 9 lights between {ev['design_floor_deg']:g}° and 45°"
        )
    kept = choose_in_design(
        st, cand, available, 9, default_floor=10.0, margin=10.0, band=(20.0, 90.0)
    )
    assert kept.design_floor == 10.0  # the key the next decision keeps as its incumbent
    assert kept.evidence()["design_floor_deg"] == 20.0 and "design_ceiling_deg" not in (
        kept.evidence()
    )
    assert (
        "above 20° (the band's floor; the designs above 0°, 10° and 20° are this one layout "
        "in the band)" in kept.reason
    )
