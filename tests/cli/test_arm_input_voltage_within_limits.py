"""An input-voltage error read while the supply is back inside the servo's voltage limits.

The servo keeps the error until a reboot, so the next command meets it with a supply that
reads right. The error had said "(input 11.1 V as read; this servo's limits are 6.0..14.0 V)"
and nothing more: a user checking the supply found it inside the limits and no reason for the
refusal. It now says the voltage is within the limits now, and that the error is kept until a
reboot, beside the command that reboots it."""

from __future__ import annotations

from pathlib import Path

from conftest import inprocess_arm_config, said, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app


def test_a_kept_input_voltage_error_says_the_supply_reads_within_the_limits(
    tmp_path: Path,
) -> None:
    # servo 1's input-voltage error already set as the port opens (the emulated supply is
    # its model's recommended voltage, inside the limits)
    cfg = inprocess_arm_config(tmp_path, servo_fault(1, 1, "input_voltage"))
    r = CliRunner(env={"COLUMNS": "400"}).invoke(app, ["check", str(cfg)])
    text = said(r)
    assert r.exit_code == 1 and "RESULT: FAIL" in text, text
    assert "servo 1: hardware fault input voltage" in text, text
    assert "within this servo's limits 6.0..14.0 V now" in text, text
    assert "is kept until a reboot" in text, text
    assert "--reboot-faulted" in text, text
    assert "this servo's limits are" not in text, text  # the outside-the-limits wording
