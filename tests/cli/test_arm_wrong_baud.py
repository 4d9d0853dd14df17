"""A rig config with the wrong baud rate for its servos fails `check` as on the rig, naming
the servo and the baud rate (the emulated servos had answered at any rate), and the rate the
servos do answer at, found by a broadcast Ping at each X-series rate (read-only, as Dynamixel
Wizard 2.0's scan): the message had left the user to scan every rate with that tool."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]


def test_check_on_the_wrong_baud_rate_names_it(tmp_path: Path) -> None:
    text = (REPO / "rig_configs" / "simulated_arm.toml").read_text()
    assert "baudrate = 57600" in text  # the servos' factory rate, set in the shipped config
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text.replace("baudrate = 57600", "baudrate = 1000000"))
    r = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    assert r.exit_code != 0, said
    assert "servo 1" in said and "at 1000000 baud" in said, said
    # no servo answers there, both at their factory 57600: the rate to set, with its key
    assert "at 1000000 baud (the [arm.dynamixel] baudrate)" in said, said
    assert "servos 1 (XL430-W250), 2 (XL430-W250) answer a broadcast ping at 57600 baud" in said
    assert "set baudrate = 57600 in [arm.dynamixel]" in said
    assert "Traceback" not in said
    assert (
        CliRunner()
        .invoke(app, ["check", str(REPO / "rig_configs" / "simulated_arm.toml")])
        .exit_code
        == 0
    )


def test_a_baud_rate_no_x_series_servo_runs_at_is_refused_at_load(tmp_path: Path) -> None:
    """38400 opens the port (dynamixel_sdk accepts it) but no X-series servo can be set to it:
    the arm had only failed at connect ("no servo answered"); now the config is refused by key,
    with the rates a servo can run at."""
    text = (REPO / "rig_configs" / "simulated_arm.toml").read_text()
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text.replace("baudrate = 57600", "baudrate = 38400"))
    r = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "arm.dynamixel.baudrate" in said and "no Dynamixel X-series servo runs at it" in said
    assert "57600, 115200, 1000000" in said
