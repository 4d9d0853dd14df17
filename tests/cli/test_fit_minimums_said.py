"""The fewest lights of each fit product are stated from one source, and every place that gates
on them or says them agrees with it.

Why: "how many lights does X need" was written out in about eight places (a literal 6 for a
PTM in the fit's gate, in the run/plan outlook and in the adaptive note; "3 for a normal" in the
fit, its signal check, the verdict and the planner; "below 6" and "15°" in the help), free to
drift apart. Each is now read from ``rti_rig.core.fit_minimums``; these tests hold the gates,
the help and the refusals to it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.app.normals_determined import undetermined_normals
from rti_rig.app.usecases import adaptive, fit, fit_rti_order
from rti_rig.app.usecases.fit_outlook import fit_needs, fit_outlook
from rti_rig.cli import app
from rti_rig.core.fit_minimums import (
    FIT_MINIMUMS,
    N_COEFFICIENTS,
    NORMAL_ERROR_LIMIT_DEG,
    NORMAL_NOISE,
)
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rti_bases import design_matrix
from rti_rig.planner.make_plan import MIN_PLAN_LIGHTS
from rti_rig.reconstruct.model_select import fewest_images
from rti_rig.reconstruct.registry import RELIGHT_MODELS, model_spec

runner = CliRunner()


def test_the_minimums_are_what_the_fit_machinery_requires() -> None:
    lights = np.array([[0.0, 0.0, 1.0]] * 20)
    for name, count in N_COEFFICIENTS.items():  # the basis itself, and the registry
        assert design_matrix(name, lights).shape[1] == count == model_spec(name).n_coefficients
    for order in (1, 2, 3):
        assert FIT_MINIMUMS.hsh(order) == (order + 1) ** 2
    assert (
        FIT_MINIMUMS.normal
        == model_spec("ps").n_coefficients
        == model_spec("lambert").n_coefficients
    )
    assert FIT_MINIMUMS.normal == MIN_PLAN_LIGHTS == fit.VERDICT_MIN_LIGHTS
    assert FIT_MINIMUMS.auto == fewest_images(RELIGHT_MODELS)
    assert FIT_MINIMUMS.rti == fewest_images(("hsh1",)) == fit_rti_order.HSH_FEWEST_LIGHTS
    assert FIT_MINIMUMS.ptm == model_spec("ptm").n_coefficients
    assert dict((f, n) for f, _, n in adaptive.RTI_FILE_LIGHTS) == {
        "fit.ptm": FIT_MINIMUMS.ptm,
        "fit.rti": FIT_MINIMUMS.rti,
    }


def test_the_outlook_turns_at_the_minimums() -> None:
    least = FIT_MINIMUMS
    assert fit_outlook(least.rti_file) is None
    assert f"a PTM needs {least.ptm}" in (fit_outlook(least.ptm - 1) or "")
    assert "too few for normals" in (fit_outlook(least.normal - 1) or "")
    assert "too few for normals" not in (fit_outlook(least.normal) or "")
    # below the normal's count the normals judgement leaves the refusal to the count
    assert undetermined_normals(fibonacci_cap(least.normal - 1, 20.0)) is None


def _help(command: str) -> str:
    r = runner.invoke(app, [command, "--help"], terminal_width=200)
    assert r.exit_code == 0, r.output
    return " ".join(r.output.replace("│", " ").split())


def test_the_help_states_the_constants() -> None:
    judged = f"more than {NORMAL_ERROR_LIMIT_DEG:g}° off at {NORMAL_NOISE:.0%} image noise"
    plan = _help("plan")
    assert f"at least {MIN_PLAN_LIGHTS}; below {FIT_MINIMUMS.rti_file} a note says" in plan
    assert judged in plan
    run = _help("run")
    assert f"At least 1; below {FIT_MINIMUMS.rti_file} a note says" in run
    assert judged in run


@pytest.mark.e2e
def test_the_refusals_state_the_constants(tmp_path: Path) -> None:
    least = FIT_MINIMUMS
    needs = fit_needs()
    assert needs == (
        f"`rti-rig fit` needs {least.normal} for a normal map with --model ps, {least.auto} "
        f"for its default --model auto, a PTM {least.ptm}, fit.rti {least.rti}"
    )
    few = MIN_PLAN_LIGHTS - 1
    r = runner.invoke(app, ["plan", "--lights", str(few), "--out", str(tmp_path / "p.lp")])
    assert r.exit_code == 2, r.output
    assert f"--lights {few}: give at least {MIN_PLAN_LIGHTS} lights to plan" in said(r)
    assert needs in said(r)
    dome = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"
    r = runner.invoke(app, ["run", str(dome), "--out", str(tmp_path / "s"), "--lights", "0"])
    assert r.exit_code == 2, r.output
    assert needs in said(r)
