"""qa.html says what its expected normal error is: a bound from the images' noise alone.

Found by measuring a 4-light session of the shipped simulated dome against its scene's true
normals: qa.html said "Expected normal error (median, bound): 0.07°", and the fitted normals
were off by 0.29° at the median and 12° at the 90th percentile (cast shadows, which the bound
does not count; with one image to spare per pixel the residual hardly shows them either).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.parametrize(
    ("lights", "spare"), [(4, "with 4 images the fit has 1 to spare"), (8, None)]
)
def test_the_expected_error_is_said_to_be_from_noise_alone(
    tmp_path: Path, lights: int, spare: str | None
) -> None:
    session, out = tmp_path / "s", tmp_path / "f"
    config = CONFIGS / "simulated_dome.toml"
    ran = runner.invoke(
        app, ["run", str(config), "--out", str(session), "--lights", str(lights), "--no-verdict"]
    )
    assert ran.exit_code == 0, ran.output
    fit = runner.invoke(app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh"])
    assert fit.exit_code == 0, fit.output
    page = " ".join((out / "qa.html").read_text(encoding="utf-8").split())
    assert "Expected normal error from image noise alone (median, bound):" in page
    assert "cast shadows, gloss and errors in the recorded lights come on top" in page
    if spare is None:
        assert "to spare per pixel" not in page
    else:
        assert spare in page
