"""A band given to ``run`` is kept: without ``--lights`` it means every LED in it, and with
``--plan`` it checks the plan's lights.

Before: ``run DOME --max-elevation-deg 30`` (no ``--lights``; docs/planning.md's advice for
gilding is a ceiling) was refused as "asked for 48 lights but the dome has only 24 LEDs between
0° and 30°", a count never given; and ``run DOME --plan P --max-elevation-deg 30`` fired P's
lights at 40° and 55°, exit 0, the band ignored and not recorded.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.core.lp_format import read_lp

REPO = Path(__file__).resolve().parents[2]
DOME = str(REPO / "rig_configs" / "simulated_dome.toml")
runner = CliRunner()


def _said(r) -> str:  # type: ignore[no-untyped-def]
    return " ".join(r.output.split())


def _elevations(lp: Path) -> np.ndarray:
    return az_el_from_direction(np.array([e.direction for e in read_lp(lp)]))[1]


def test_a_ceiling_alone_shoots_every_led_under_it_and_resumes_with_its_line(
    tmp_path: Path,
) -> None:
    out = tmp_path / "s"
    line = ["run", DOME, "--out", str(out), "--max-elevation-deg", "30", "--no-verdict"]
    r = runner.invoke(app, line)
    assert r.exit_code == 0, _said(r)
    el = _elevations(out / "lights.lp")
    assert len(el) == 24 and el.max() <= 30.0 + 1e-6  # the shipped dome's 24 LEDs up to 30°
    r = runner.invoke(app, [*line, "--resume", str(out)])  # the same line: the same session
    assert r.exit_code == 0 and "this session is complete" in _said(r), _said(r)


def test_a_plan_outside_the_band_given_with_it_is_refused_by_line(tmp_path: Path) -> None:
    plan = tmp_path / "p.lp"
    r = runner.invoke(app, ["plan", "--rig", DOME, "--lights", "12", "--out", str(plan)])
    assert r.exit_code == 0, _said(r)
    high = int((_elevations(plan) > 30.0 + 1e-6).sum())
    assert 0 < high < 12
    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", DOME, "--plan", str(plan), "--max-elevation-deg", "30", "--out", str(out)]
    )
    assert r.exit_code == 2, _said(r)
    text = _said(r)
    assert f"{high} of its 12 lights lie outside --max-elevation-deg 30" in text, text
    assert "line " in text and "nothing was lit" in text
    assert not out.exists()
    # a band that holds the plan's lights: it runs, each light the plan's
    r = runner.invoke(
        app,
        [
            "run",
            DOME,
            "--plan",
            str(plan),
            "--max-elevation-deg",
            "80",
            "--out",
            str(out),
            "--no-verdict",
        ],
    )
    assert r.exit_code == 0, _said(r)
    np.testing.assert_allclose(_elevations(out / "lights.lp"), _elevations(plan), atol=1e-3)


def test_a_band_holding_no_led_is_said_of_the_band_not_of_a_count(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", DOME, "--out", str(out), "--max-elevation-deg", "5"])
    assert r.exit_code == 2, _said(r)
    text = _said(r)
    assert "the dome has no LED between 0° and 5° elevation (its LEDs stand between" in text
    assert "asked for" not in text and not out.exists()


def test_plan_lights_on_the_band_edge_written_to_six_decimals_are_inside(tmp_path: Path) -> None:
    """A ring at 40° written as an .lp writes it (six decimals) sits 3e-5° off 40: it had been
    refused as "at 40.0°" outside --max-elevation-deg 40."""
    import math

    lines = []
    for i, el in enumerate([20.0] * 6 + [40.0] * 6):
        az = math.radians(60 * i + (30 if el == 40.0 else 0))
        e = math.radians(el)
        x, y, z = math.cos(e) * math.cos(az), math.cos(e) * math.sin(az), math.sin(e)
        lines.append(f"img_{i:02d}.jpg {x:.6f} {y:.6f} {z:.6f}")
    plan = tmp_path / "ring.lp"
    plan.write_text(f"{len(lines)}\n" + "\n".join(lines) + "\n")
    arm = str(REPO / "rig_configs" / "virtual_arm.toml")
    out = tmp_path / "s"
    r = runner.invoke(
        app,
        [
            "run",
            arm,
            "--plan",
            str(plan),
            "--max-elevation-deg",
            "40",
            "--out",
            str(out),
            "--no-verdict",
        ],
    )
    assert r.exit_code == 0, _said(r)


def test_a_replay_band_holding_no_image_is_said_of_its_images(tmp_path: Path) -> None:
    acq = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
    r = runner.invoke(
        app, ["run", str(acq), "--out", str(tmp_path / "s"), "--max-elevation-deg", "1"]
    )
    assert r.exit_code == 2, _said(r)
    text = _said(r)
    assert "the acquisition" in text and "has no image between 0° and 1° elevation" in text, text
    assert "widen --max-elevation-deg 1" in text and "LED" not in text, text
