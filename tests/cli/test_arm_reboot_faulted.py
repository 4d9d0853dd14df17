"""``rti-rig check RIG.toml --reboot-faulted`` clears a servo's hardware error, and nothing else.

A servo that overloads latches its Hardware Error Status and (on the XL430, whose Shutdown
selects overload) switches its torque off until a Reboot (ROBOTIS e-manual, Shutdown (63)).
The driver had a ``reboot()``, but no command reached it: users were sent to a power cycle or
Dynamixel Wizard. The option reboots only the faulted servos whose torque is off, reads their
status back and says what it established; it writes no goal and switches no torque on, so the
arm does not move: a later ``check`` or ``run`` connects it through every check.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, emulators_built_by_check, inprocess_arm_config, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel import protocol2 as p2

runner = CliRunner()

# the elevation servo overloads as the first instruction packet arrives (the arm already
# faulted when rti-rig opens the port, as after a session that stopped on it)
FAULT = servo_fault(1, 2)


def _config(tmp_path: Path) -> Path:
    return inprocess_arm_config(tmp_path, FAULT)


def test_reboot_faulted_clears_the_faulted_servo_only_and_moves_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    emulators = emulators_built_by_check(monkeypatch)
    cfg = _config(tmp_path)
    r = runner.invoke(app, ["check", str(cfg), "--reboot-faulted"], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "Traceback" not in said
    assert said.startswith(f"Looking for faulted servos on {cfg}'s arm (nothing moves)"), said
    assert "servo 1 (azimuth): no hardware fault (Hardware Error Status 0x00): not rebooted" in (
        said
    )
    assert (
        "servo 2 (elevation): hardware fault overload (0x20); rebooted, Hardware Error Status "
        "read back 0x00, torque off" in said
    ), said
    assert "RESULT: PASS" in said
    # waiting for the rebooted servo is one wait, not a warning per unanswered ping
    assert not [r for r in caplog.records if "retrying once" in r.getMessage()]
    (emu,) = emulators
    # the truth: servo 2 alone was rebooted, its error cleared; nothing moved or was driven
    reboots = [p.dxl_id for p in emu.instructions if p.instruction == p2.INST_REBOOT]
    assert reboots == [2]
    assert emu.servos[2].get(ct.HARDWARE_ERROR_STATUS) == 0
    assert all(s.get(ct.TORQUE_ENABLE) == 0 for s in emu.servos.values())
    assert emu.goal_log == []
    writes = [p for p in emu.instructions if p.instruction == p2.INST_WRITE]
    assert writes == []


@pytest.mark.parametrize(
    "rig",
    [
        CONFIGS / "emulated_nab_rti_v1.toml",
        Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay" / "dirs.lp",
    ],
)
def test_reboot_faulted_is_refused_on_a_rig_without_dynamixel_servos(rig: Path) -> None:
    r = runner.invoke(app, ["check", str(rig), "--reboot-faulted"], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "--reboot-faulted reboots a Dynamixel arm's faulted servos" in said
    # a dome or a recorded acquisition was said to have an arm ("Looking for faulted servos
    # on dirs.lp's arm") before the refusal
    assert "Looking for faulted servos" not in said, said


def test_a_faulted_servo_whose_torque_is_on_is_left_alone_and_the_user_told_what_to_do(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An input-voltage error, which the XL430's Shutdown (0x34) does not select: the servo
    keeps its torque on and holds its joint. A Reboot resets its RAM, torque included (ROBOTIS
    e-manual, Reboot; Torque Enable (64) is RAM), and the loaded elevation joint would drop: it
    is skipped, and the report says which servo, why, the fault's cause to fix first (a power
    cycle alone on the supply that faulted it faults it again) and what to do then."""
    from rti_rig.drivers.dynamixel.arm import DynamixelArm

    emulators = emulators_built_by_check(monkeypatch)
    real_reboot = DynamixelArm.reboot_faulted

    def reboot_faulted(self):  # type: ignore[no-untyped-def]
        servo = emulators[0].servos[2]  # as a session left it: torque on, then the fault
        servo._set(ct.TORQUE_ENABLE, 1)
        servo._set(ct.HARDWARE_ERROR_STATUS, int(ct.HardwareFault.INPUT_VOLTAGE))
        return real_reboot(self)

    monkeypatch.setattr(DynamixelArm, "reboot_faulted", reboot_faulted)
    cfg = inprocess_arm_config(tmp_path)
    r = runner.invoke(app, ["check", str(cfg), "--reboot-faulted"], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert (
        "servo 2 (elevation): hardware fault input voltage (0x01) but its torque is on (it "
        "still holds its joint): NOT rebooted, as a reboot switches torque off and the joint "
        "would drop; check the power supply voltage against the servo's limits, then support "
        "the arm and delete " in said
    ), said
    # an emulated chain has no power switch: its power cycle is deleting its kept state
    assert (
        "(where the emulated servos' powered state and latched errors are kept: their power "
        "off and on)"
    ) in said
    assert "switch the servos' power" not in said, said
    assert "nothing rebooted; no torque was switched on or off" in said
    assert "RESULT: FAIL" in said
    (emu,) = emulators  # the truth: no Reboot sent, the joint still held
    assert not [p for p in emu.instructions if p.instruction == p2.INST_REBOOT]
    assert emu.servos[2].get(ct.TORQUE_ENABLE) == 1
