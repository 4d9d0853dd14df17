"""`--until-error` weighs the pixels the fit does not explain (the images' misfit bound).

On the shipped simulated arm under a ceiling of 15°, the robust fit keeps observations a cast
shadow darkened without making them dark; 6 % of the pixels (the tablet's steep walls) erred by
more than 10°, the point estimate (simulated on an object model with no such penumbra) did not
see them, and the stop claimed 1.5° at 11 lights where the session measured 2.5° (0.8° at 82
lights, measuring 2.3°). The upper estimate is now the larger
of the simulated one and a bound from the images' own residuals (``planner.adaptive_until.
misfit_deg``), taken at the camera's resolution (docs/adaptive.md, "The images' own misfit").
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

CONFIGS = Path(__file__).resolve().parents[2] / "rig_configs"
ARM = CONFIGS / "simulated_arm.toml"
DOME = CONFIGS / "simulated_dome.toml"
runner = CliRunner()


def _measured_deg(config: Path, session: Path) -> float:
    from benchmarks.until_error_configs import session_error_deg

    return session_error_deg(config, session)


def _run(*args: str) -> str:
    r = runner.invoke(app, ["run", *args, "--no-verdict"])
    assert r.exit_code == 0, r.output
    return " ".join(r.output.split())


def _result(session: Path) -> dict:  # type: ignore[type-arg]
    return json.loads((session / "manifest.json").read_text())["adaptive"]["result"]


def test_grazing_lights_over_a_relief_are_not_claimed_on_the_model_alone(tmp_path: Path) -> None:
    """The shipped arm under 15°: the upper estimate stands above the error the session
    measures (before: 0.5–1.4° against 2.3–3.4°), the claim is not made, and the stop says
    which term held it."""
    out = tmp_path / "s"
    said = _run(
        str(ARM), "--out", str(out), "--until-error", "1.5", "--max-elevation-deg", "15",
        "--lights", "16",
    )  # fmt: skip
    result = _result(out)
    measured = _measured_deg(ARM, out)
    assert result["upper_error_deg"] >= measured, (result, measured)
    assert not result["target_claimed"], said
    # the misfit bound is what stands above the simulated term here, and the stop says so
    assert result["misfit_deg"] > result["upper_factor"] * result["estimated_error_deg"], result
    assert "misfit bound" in said and "pixels the fit does not explain" in said, said


def test_the_bound_holds_nothing_back_on_a_surface_the_fit_explains(tmp_path: Path) -> None:
    """The shipped dome over every elevation (a relief under directional lights the fit
    explains): the bound stays near zero, the claim comes as it did and holds."""
    out = tmp_path / "s"
    said = _run(str(DOME), "--out", str(out), "--until-error", "1.5")
    result = _result(out)
    assert result["target_claimed"], said
    assert result["lights_used"] <= 6, result  # 5 in the benchmark's run, before and after
    assert result["misfit_deg"] is not None and result["misfit_deg"] < 0.2, result
    assert "misfit bound" not in result["stop"]["reason"], result
    assert _measured_deg(DOME, out) <= 1.5


def test_each_decision_records_the_bound_it_weighed(tmp_path: Path) -> None:
    """Every decision with an estimate records the bound, and its upper estimate is the larger
    term plus the unsolved one (the record is what a reader checks the stop against)."""
    out = tmp_path / "s"
    _run(
        str(ARM), "--out", str(out), "--until-error", "1.5", "--max-elevation-deg", "15",
        "--lights", "8",
    )  # fmt: skip
    lines = (out / "journal.jsonl").read_text(encoding="utf-8").splitlines()
    decisions = [json.loads(line)["decision"] for line in lines][4:]
    assert decisions, lines
    for d in decisions:
        first = max(d["estimated_error_deg"] * d["upper_factor"], d["misfit_deg"] or 0.0)
        expected = first + d["unsolved_fraction"] * d["unsolved_deg"]
        assert d["upper_error_deg"] == pytest.approx(expected, abs=0.01), d


def test_a_session_begun_before_the_bound_is_judged_with_it(tmp_path: Path) -> None:
    """A session whose settings do not record the bound's noise allowance (begun by an earlier
    build) resumes — the bound decides only when to stop — and is judged with it."""
    from conftest import begun_before, interrupted

    out = tmp_path / "s"
    interrupted(ARM, out, after_step=5, lights=10, until=1.5, band=(0.0, 15.0))
    begun_before(out, "misfit_noise_k", "planner.adaptive_until.MISFIT_NOISE_K")
    said = _run("--resume", str(out))
    result = _result(out)
    assert result["misfit_deg"] is not None and not result["target_claimed"], said
    assert result["upper_error_deg"] >= _measured_deg(ARM, out), result
