"""A refusal of an adaptive session names the option the user gave.

``run RIG --out X --until-error 2 --plan P`` had said "--adaptive chooses its own lights: drop
--plan", of an option never typed; ``--until-error`` makes the session adaptive, and the
refusal now says so. Its siblings (metering, a camera-triggered dome) had the same slip.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
DOME = str(REPO / "rig_configs" / "simulated_dome.toml")


def _run(args: list[str]) -> str:
    r = CliRunner().invoke(app, ["run", *args])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert "Traceback" not in text
    return text


@pytest.mark.parametrize(
    ("given", "named"),
    [
        (["--until-error", "2"], "--until-error (an adaptive session)"),
        (["--adaptive", "--lights", "12"], "--adaptive"),
    ],
)
def test_plan_with_an_adaptive_session_names_the_option_given(
    tmp_path: Path, given: list[str], named: str
) -> None:
    text = _run([DOME, "--out", str(tmp_path / "X"), *given, "--plan", str(tmp_path / "lights.lp")])
    assert f"error: {named} chooses its own lights: drop --plan" in text, text
    assert not (tmp_path / "X").exists()


def test_metering_an_until_error_session_names_until_error(tmp_path: Path) -> None:
    text = _run([DOME, "--out", str(tmp_path / "X"), "--until-error", "2", "--auto-exposure"])
    assert "--until-error (an adaptive session) cannot meter the exposure" in text, text
    assert "--adaptive" not in text


def test_a_camera_triggered_dome_names_until_error(tmp_path: Path) -> None:
    cfg = str(REPO / "rig_configs" / "emulated_cceh_rti.toml")
    text = _run([cfg, "--out", str(tmp_path / "X"), "--until-error", "2"])
    assert "--until-error (an adaptive session) cannot be used with a camera-triggered" in text
    assert "--adaptive" not in text
