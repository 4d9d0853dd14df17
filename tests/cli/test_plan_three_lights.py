"""Three lights are planned as the orthogonal triad, through the CLI on the shipped rigs.

Three lights are the fewest that determine a normal (``rti-rig fit --model ps``). The plan of
three had been the equal-area spiral every other count uses, which on the shipped dome put one
light at 10° (10°, 40°, 55°): the plan then said its lights determined a normal "only while the
object is level", and on the real 72-LED dome three such lights measured 16.9° against 9.9° for
three lights 120° apart at 35° (``python -m benchmarks.three_lights``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.core.lp_format import read_lp

CONFIGS = Path(__file__).resolve().parents[2] / "rig_configs"


def _plan(tmp_path: Path, config: str, *extra: str) -> tuple[np.ndarray, str]:
    out = tmp_path / "plan.lp"
    r = CliRunner().invoke(
        app,
        ["plan", "--rig", str(CONFIGS / config), "--lights", "3", "--out", str(out), *extra],
    )
    assert r.exit_code == 0, r.output
    return np.array([e.direction for e in read_lp(out)]), " ".join(r.output.split())


def _azimuth_gaps(lights: np.ndarray) -> np.ndarray:
    az, _ = az_el_from_direction(lights)
    a = np.sort(az)
    return np.diff(np.append(a, a[0] + 360.0))


@pytest.mark.parametrize("method", ["uniform", "optimal"])
def test_the_shipped_dome_plans_three_lights_on_one_ring(tmp_path: Path, method: str) -> None:
    lights, said = _plan(tmp_path, "simulated_dome.toml", "--method", method)
    _, el = az_el_from_direction(lights)
    # the shipped dome's ring nearest 35.26° is its 40° ring
    np.testing.assert_allclose(el, 40.0, atol=0.5)
    # its 10 LEDs stand 36° apart: gaps of 108°, 144°, 108° are as near to 120° as it has
    np.testing.assert_allclose(np.sort(_azimuth_gaps(lights)), [108.0, 108.0, 144.0], atol=0.5)
    assert "tilted up to 30° in any direction" in said
    assert "only while the object is level" not in said


def test_an_arm_plans_the_exact_triad(tmp_path: Path) -> None:
    lights, said = _plan(tmp_path, "virtual_arm.toml")
    np.testing.assert_allclose(lights.T @ lights, np.eye(3), atol=1e-5)
    assert "tilted up to 25° in any direction" in said


def test_a_ceiling_below_the_triad_holds_it_at_the_ceiling(tmp_path: Path) -> None:
    lights, said = _plan(tmp_path, "virtual_arm.toml", "--max-elevation-deg", "30")
    _, el = az_el_from_direction(lights)
    np.testing.assert_allclose(el, 30.0, atol=0.01)
    np.testing.assert_allclose(_azimuth_gaps(lights), 120.0, atol=0.01)
    assert "tilted up to 20° in any direction" in said


def test_a_three_light_session_is_shot_on_the_ring_and_fitted(tmp_path: Path) -> None:
    """The front door whole: ``run --lights 3`` shoots the triad, and ``fit --model ps`` makes
    its normal map."""
    session = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(session), "--lights", "3"]
    )
    assert r.exit_code == 0, r.output
    # the next step named is the fit that takes 3 lights (the default --model auto refuses
    # them, and "Next: rti-rig fit S --out S-fit" had been said all the same)
    said = " ".join(r.output.split())
    fit_ps = f"rti-rig fit {session} --out {session}-fit --model ps"
    assert f"Next: {fit_ps}" in said, said
    # so is every other message that names a complete session's next step: a resume of it,
    # and a resume asking another request of it (both had named the plain fit)
    dome = str(CONFIGS / "simulated_dome.toml")
    for options, words in (
        ([], f"nothing to resume, nothing was changed. Next: {fit_ps}"),
        (["--lights", "4"], f"To use the session as it is: {fit_ps}"),
    ):
        r = CliRunner().invoke(app, ["run", dome, "--resume", str(session), *options])
        assert r.exit_code == (2 if options else 0), r.output
        assert words in " ".join(r.output.split()), r.output
    _, el = az_el_from_direction(np.array([e.direction for e in read_lp(session / "lights.lp")]))
    np.testing.assert_allclose(el, 40.0, atol=0.5)
    r = CliRunner().invoke(
        app, ["fit", str(session), "--out", str(tmp_path / "fit"), "--model", "ps"]
    )
    assert r.exit_code == 0, r.output
    normals = np.load(tmp_path / "fit" / "normals.npy")
    assert np.isfinite(normals).all() and normals[..., 2].mean() > 0.5


def _plan_on_arm_turning(tmp_path: Path, half: float) -> tuple[np.ndarray, str]:
    """``plan --lights 3`` on the shipped servo arm with its base limited to ±``half``°."""
    text = (CONFIGS / "simulated_arm.toml").read_text(encoding="utf-8")
    assert text.count("min_deg = -170.0") == 1 and text.count("max_deg = 170.0") == 1
    config = tmp_path / "limited_arm.toml"
    config.write_text(
        text.replace("min_deg = -170.0", f"min_deg = {-half}").replace(
            "max_deg = 170.0", f"max_deg = {half}"
        ),
        encoding="utf-8",
    )
    out = tmp_path / "plan.lp"
    r = CliRunner().invoke(app, ["plan", "--rig", str(config), "--lights", "3", "--out", str(out)])
    assert r.exit_code == 0, r.output
    return np.array([e.direction for e in read_lp(out)]), " ".join(r.output.split())


def test_an_arm_turning_half_way_round_spreads_the_three_lights(tmp_path: Path) -> None:
    """The shipped servo arm with its base limited to ±90° (a cable, a wall): the triad mapped
    linearly into that range had stood at -60°, 0° and 60° (noise bound tr (LᵀL)⁻¹ = 19,
    against 3 for the triad). Now the triad's ring at the range's limits and middle: -90°, 0°
    and 90° (bound 4.5), still at 35.26°, so a 25° tilt still faces all three."""
    lights, said = _plan_on_arm_turning(tmp_path, 90.0)
    az, el = az_el_from_direction(lights)
    np.testing.assert_allclose(
        np.sort(np.where(az > 180.0, az - 360.0, az)), [-90, 0, 90], atol=0.01
    )
    np.testing.assert_allclose(el, 35.26, atol=0.01)
    assert np.trace(np.linalg.inv(lights.T @ lights)) == pytest.approx(4.5, abs=1e-3)
    assert "tilted up to 25° in any direction" in said


def test_an_arm_turning_only_thirty_degrees_still_plans_a_normal_map(tmp_path: Path) -> None:
    """A base joint limited to ±15°: three lights on one ring were refused ("cannot determine
    a surface normal ... leave no other choice", though the arm reaches other elevations);
    now the middle one stands at the band's top and the plan is written."""
    lights, said = _plan_on_arm_turning(tmp_path, 15.0)
    assert np.linalg.cond(lights) < 10.0
    assert "tilted up to 25° in any direction" in said


@pytest.mark.parametrize("lights", [1, 2])
def test_a_test_shot_names_no_fit_as_its_next_step(tmp_path: Path, lights: int) -> None:
    """1 or 2 lights: a test shot, which no fit takes; the run had ended "Next: rti-rig fit
    S --out S-fit", which fit then refused."""
    session = tmp_path / "s"
    r = CliRunner().invoke(
        app,
        [
            "run",
            str(CONFIGS / "simulated_dome.toml"),
            "--out",
            str(session),
            "--lights",
            str(lights),
        ],
    )
    assert r.exit_code == 0, r.output
    said = " ".join(r.output.split())
    next_said = said.split("Next: ", 1)[1]
    assert next_said.startswith("no fit: ") and "rti-rig fit" not in next_said, said
    r = CliRunner().invoke(app, ["fit", str(session), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 2  # as the run said: no fit takes it
