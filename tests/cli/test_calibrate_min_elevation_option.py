"""``calibrate-lights --min-elevation-deg`` out of range is refused by the option's own name.

It had said ``min_elevation_deg must be in (0, 90), got 0.0`` (an internal name) and ``--help``
never gave the range; the refusal now names the option, the range and the default, before the
card session is read.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("value", ["0", "-5", "90", "nan"])
def test_an_elevation_out_of_range_names_the_option_range_and_default(
    tmp_path: Path, value: str
) -> None:
    r = CliRunner().invoke(
        app,
        [
            "calibrate-lights",
            str(tmp_path / "card"),
            "--rig",
            str(REPO / "rig_configs" / "simulated_dome.toml"),
            "--min-elevation-deg",
            value,
        ],
    )
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert f"--min-elevation-deg {value}: give an elevation above 0 and below 90 degrees" in text
    assert "(the default is 5)" in text
    assert "min_elevation_deg" not in text and "Traceback" not in text


def test_help_states_the_range() -> None:
    r = CliRunner().invoke(app, ["calibrate-lights", "--help"], terminal_width=200)
    text = " ".join(r.output.replace("│", " ").split())
    assert r.exit_code == 0, text
    assert "Degrees, above 0 and below 90." in text, text
