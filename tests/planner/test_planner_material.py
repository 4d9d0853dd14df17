"""A declared surface (``material``): what the user knows of the object and no preview shows.

One preview of a flat glossy object (a gilded icon) does not show its gloss, so the planner's
highlight hint reads ≈ 0 there; ``material="glossy"`` makes it model a broad highlight lobe
anyway, and the lights it then chooses keep away from the mirror direction.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import direction_from_az_el, fibonacci_cap
from rti_rig.core.lp_format import read_lp
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.make_plan import plan_with_report
from rti_rig.planner.objectives import (
    GLOSSY_SPECULAR,
    GLOSSY_WIDTH_DEG,
    HIGHLIGHT_WEIGHT_WIDTH_DEG,
    candidates_for,
    light_weights,
    reflectance,
)
from rti_rig.planner.surface_estimate import estimate_surface, flat_surface, sample_surface

DATA = Path(__file__).resolve().parents[1] / "data" / "neuralrti"
_LP = read_lp(DATA / "dirs.lp")
REAL_DOME = DomeGeometry(np.array([e.direction for e in _LP]), tuple(e.name for e in _LP))
DOME = DomeGeometry(fibonacci_cap(96, 3.0, 88.0), tuple(f"led{i:02d}" for i in range(96)))


def _mirror_strength(directions: np.ndarray) -> np.ndarray:
    """How close each light's mirror highlight on a level surface is to the camera (0..1)."""
    half = directions + np.array([0.0, 0.0, 1.0])
    half /= np.linalg.norm(half, axis=1, keepdims=True)
    angle = np.degrees(np.arccos(np.clip(half[:, 2], -1.0, 1.0)))
    return np.exp(-((angle / GLOSSY_WIDTH_DEG) ** 2))


def test_sample_models_the_declared_surface() -> None:
    """auto: the preview's hint (none for a level grey surface); matte: none; glossy: the
    declared strength and lobe width, which lower the weight of a light near the mirror."""
    d = np.stack([direction_from_az_el(0, 88), direction_from_az_el(0, 20)])
    cands = candidates_for(DomeGeometry(d, ("zenith", "low")))
    held = fibonacci_cap(16, 3.0, 88.0)
    surface = flat_surface()
    auto = sample_surface(surface, cands, held, material="auto")
    matte = sample_surface(surface, cands, held, material="matte")
    glossy = sample_surface(surface, cands, held, material="glossy")
    assert auto.specular == matte.specular == 0.0 and auto.highlight_width_deg is None
    assert glossy.specular == GLOSSY_SPECULAR and glossy.highlight_width_deg == GLOSSY_WIDTH_DEG
    w_auto = light_weights(auto, d)[: auto.base_count].mean(axis=0)
    w_glossy = light_weights(glossy, d)[: glossy.base_count].mean(axis=0)
    assert w_glossy[0] < 0.3 * w_auto[0]  # the near-zenith light mirrors into the camera
    assert w_glossy[1] > 0.5 * w_auto[1]  # a low light barely does
    # the lobe is broader than the one the preview's hint is modelled with
    assert GLOSSY_WIDTH_DEG > HIGHLIGHT_WEIGHT_WIDTH_DEG


def test_declaration_overrides_the_preview_hint() -> None:
    """A surface whose preview showed highlights: auto models them, matte removes them, glossy
    replaces them by the declared lobe — in the reflectance the relight objective fits too,
    where a 30° lobe still lights a 30°-elevation light's mirror path and the hint's 10° one
    does not."""
    flat = flat_surface()
    shiny = dataclasses.replace(flat, fit=dataclasses.replace(flat.fit, bright_outliers=0.05))
    d = np.stack([direction_from_az_el(0, 90), direction_from_az_el(0, 30)])
    cands = candidates_for(DomeGeometry(d, ("zenith", "el30")))
    held = fibonacci_cap(16, 3.0, 88.0)
    smp = {m: sample_surface(shiny, cands, held, material=m) for m in ("auto", "matte", "glossy")}
    assert smp["auto"].specular == pytest.approx(0.45)  # 10 × (0.05 − 0.005)
    assert smp["matte"].specular == 0.0
    assert smp["glossy"].specular == GLOSSY_SPECULAR
    level = np.array([[0.0, 0.0, 1.0]])
    lit = np.ones((1, 2))
    f = {
        m: reflectance(dataclasses.replace(smp[m], normals=level), d, lit)[0]
        for m in ("auto", "matte", "glossy")
    }
    lambert = d[:, 2]
    assert f["matte"] == pytest.approx(lambert)
    assert f["auto"][0] == pytest.approx(lambert[0] + 0.45)  # the hint's lobe at the mirror
    assert f["auto"][1] - lambert[1] < 0.01  # 30° off the mirror: outside a 10° lobe
    assert f["glossy"][0] == pytest.approx(lambert[0] + GLOSSY_SPECULAR)
    assert f["glossy"][1] - lambert[1] == pytest.approx(GLOSSY_SPECULAR * np.exp(-1.0), rel=1e-6)


def test_declared_glossy_keeps_lights_off_the_mirror_direction() -> None:
    """A level surface, no preview (so no hint): planned as glossy for normals, the lights'
    mirror highlights stay further from the camera than planned as matte (the nearest one
    and in sum), and the report says why."""
    dirs = {}
    for material in ("auto", "glossy"):
        sched, report = plan_with_report(None, DOME, 12, "optimal", material=material)
        assert len({s.led for s in sched.steps}) == 12
        dirs[material] = sched.directions
    text = " ".join(report.lines())
    assert "declared glossy" in text and "level, glossy surface" in text
    assert report.material == "glossy"
    glossy, auto = _mirror_strength(dirs["glossy"]), _mirror_strength(dirs["auto"])
    assert glossy.max() < auto.max() - 0.1
    assert glossy.sum() < 0.9 * auto.sum()


def test_declared_glossy_reaches_the_relight_objective() -> None:
    """The relight objective models the declared lobe in its reflectance: its plan changes.
    (Whether for the better is the benchmarks' question: docs/research/planner.md.)"""
    plans = {
        m: plan_with_report(None, DOME, 12, "optimal", "relight", material=m)
        for m in ("auto", "glossy")
    }
    assert {s.led for s in plans["auto"][0].steps} != {s.led for s in plans["glossy"][0].steps}
    assert any("declared glossy" in n for n in plans["glossy"][1].notes)


def test_declared_glossy_on_a_real_preview() -> None:
    """On the gilded icon's own preview the hint reads ≈ 0 (so auto models no gloss); the
    declaration changes the plan and is reported."""
    import cv2

    rgb = cv2.cvtColor(cv2.imread(str(DATA / "image11_small.jpg")), cv2.COLOR_BGR2RGB)
    surface = estimate_surface(rgb, None)
    assert surface.fit.bright_outliers < 0.01
    plans = {
        m: plan_with_report(rgb, REAL_DOME, 9, "optimal", material=m)[0] for m in ("auto", "glossy")
    }
    assert {s.led for s in plans["auto"].steps} != {s.led for s in plans["glossy"].steps}


def test_material_is_checked_and_reported_when_unused() -> None:
    with pytest.raises(ScheduleError, match="--material 'shiny' is not known; choose auto"):
        plan_with_report(None, DOME, 6, "optimal", material="shiny")
    # uniform without a preview models no surface: the declaration cannot change anything
    _, report = plan_with_report(None, DOME, 6, "uniform", material="glossy")
    assert any("--material glossy is not used" in n for n in report.notes)
    # uniform with a preview: the expected errors use it, the lights do not change
    preview = np.full((32, 32), 128, np.uint8)
    a, report = plan_with_report(
        preview, DOME, 6, "uniform", "normals", (0.0, 60.0), material="glossy"
    )
    b, _ = plan_with_report(preview, DOME, 6, "uniform", "normals", (0.0, 60.0))
    assert [s.led for s in a.steps] == [s.led for s in b.steps]
    assert any("changes only the expected errors" in n for n in report.notes)


@pytest.mark.e2e
def test_cli_material(tmp_path: Path) -> None:
    """--material reaches the planner (its note is printed); a bad value is refused before
    anything is written."""
    runner = CliRunner()
    base = ["plan", "--rig", str(DATA / "dirs.lp"), "--method", "optimal", "--lights", "9"]
    r = runner.invoke(app, [*base, "--material", "glossy", "--out", str(tmp_path / "a.lp")])
    assert r.exit_code == 0, r.output
    assert "declared glossy" in r.output and len(read_lp(tmp_path / "a.lp")) == 9
    r = runner.invoke(app, [*base, "--material", "shiny", "--out", str(tmp_path / "b.lp")])
    assert r.exit_code == 2 and "--material 'shiny' is not known" in said(r)
    assert not (tmp_path / "b.lp").exists()
    # refused before the rig is read: its own error, not the missing rig's
    missing = ["plan", "--rig", str(tmp_path / "nowhere.toml"), "--material", "shiny"]
    r = runner.invoke(app, [*missing, "--out", str(tmp_path / "c.lp")])
    assert r.exit_code == 2 and "--material 'shiny' is not known" in said(r)
