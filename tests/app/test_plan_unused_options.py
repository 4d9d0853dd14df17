"""`rti-rig plan` says when a modelling option it was given is not used
(rti_rig/app/usecases/plan.py).

Why: `--method uniform --signal-noise 0.05` planned without a word, as if the JPEG noise had
been modelled, while `--material glossy` in the same place is noted as unused.
"""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
PLAN = ["plan", "--rig", str(CONFIGS / "simulated_dome.toml"), "--method"]


def test_signal_noise_given_to_a_plan_that_models_no_surface_is_noted(tmp_path: Path) -> None:
    out = str(tmp_path / "u.lp")
    r = runner.invoke(app, [*PLAN, "uniform", "--signal-noise", "0.05", "--out", out])
    assert r.exit_code == 0, r.output
    assert "--signal-noise 0.05 is not used: no surface was modelled (uniform needs none)" in (
        said(r)
    )


def test_signal_noise_modelled_by_optimal_gets_no_such_note(tmp_path: Path) -> None:
    out = str(tmp_path / "o.lp")
    r = runner.invoke(app, [*PLAN, "optimal", "--signal-noise", "0.05", "--out", out])
    assert r.exit_code == 0, r.output
    assert "is not used" not in said(r)
    assert "noise modelled: 5 % of the signal" in said(r)
