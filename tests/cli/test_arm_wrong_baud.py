"""A rig config with the wrong baud rate for its servos fails `check` as on the rig, naming
the servo and the baud rate (the emulated servos had answered at any rate)."""

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
    # no servo at all answers a broadcast ping there: the baud rate is named with its key
    assert "no servo at all answers a broadcast ping at 1000000 baud" in said
    assert "[arm.dynamixel] baudrate (X-series servos ship at 57600" in said
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
