"""A plan for a declared glossy surface does not say, lines after "declared glossy: highlights
modelled as a 30° lobe", that its expected errors count "not gloss": they count the declared
lobe, not the object's own gloss beyond it."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app


@pytest.mark.parametrize("material", ["glossy", "matte"])
def test_the_expected_errors_caveat_agrees_with_the_declared_material(
    tmp_path: Path, material: str
) -> None:
    argv = ["plan", "--rig", str(CONFIGS / "simulated_dome.toml"), "--lights", "9"]
    argv += ["--method", "optimal", "--material", material, "--out", str(tmp_path / "p.lp")]
    r = CliRunner().invoke(app, argv)
    assert r.exit_code == 0, said(r)
    caveat = said(r).split("the expected errors count the camera noise")[1]
    if material == "glossy":
        assert "declared glossy: highlights modelled as a 30° lobe" in said(r), said(r)
        assert "not gloss," not in caveat and "beyond the declared lobe" in caveat, caveat
    else:
        assert "on the modelled surface only, not gloss, shadows or relief" in caveat, caveat
