"""A servo's own hardware error is rehearsed on an emulated arm through ``[[emulator.faults]]``.

A real X-series servo that overloads sets its Hardware Error Status bit, flags the Alert bit
in every status packet and, for the faults its Shutdown (63) selects (overload on the XL430),
switches its torque off until a reboot (ROBOTIS e-manual): the arm sags. The emulator could
raise it, but nothing at the front door could: an arm config's faults were only lost or
damaged replies, so ``run`` and ``check`` on a servo that overloads mid-move could not be
rehearsed (an ``overload`` fault was refused at load).
"""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest
from conftest import CONFIGS, emulators_built_by_check, inprocess_arm_config, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.dynamixel import control_table as ct

runner = CliRunner()

FAULT = servo_fault(60, 2)


def _config(tmp_path: Path, extra: str = FAULT) -> Path:
    return inprocess_arm_config(tmp_path, extra)


def test_check_on_a_servo_that_overloads_stops_names_it_and_leaves_it_unparked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    emulators = emulators_built_by_check(monkeypatch)
    r = runner.invoke(app, ["check", str(_config(tmp_path))], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert "Traceback" not in said
    assert "servo 2: hardware fault overload (Hardware Error Status 0x20)" in said, said
    # the command names the config checked (it had said "RIG.toml", a placeholder)
    assert f"run rti-rig check {shlex.quote(str(tmp_path / 'arm.toml'))} --reboot-faulted" in said
    assert "NOT parked" in said and "RESULT: FAIL" in said
    # the fault's paragraph is said once (it was printed three times: the pose's row, ABORTED
    # and the teardown's stop), and the teardown still says what it met
    assert said.count("clear the obstruction") == 1, said
    assert said.count("servo 2: hardware fault overload") == 2  # ABORTED, then the pointer
    assert "(as under ABORTED above)" in said and "(the arm may sag)" in said
    (emu,) = emulators
    servo = emu.servos[2]
    # the servo as a real one: shut down (torque off), its error latched until a reboot
    assert servo.get(ct.TORQUE_ENABLE) == 0 and servo.shut_down
    assert servo.get(ct.HARDWARE_ERROR_STATUS) & ct.HardwareFault.OVERLOAD


def test_a_hardware_fault_needs_one_of_the_arms_servos_and_is_refused_on_a_dome(
    tmp_path: Path,
) -> None:
    wrong = FAULT.replace("servo_id = 2", "servo_id = 7")
    r = runner.invoke(app, ["check", str(_config(tmp_path, wrong))], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "emulator.faults[0].servo_id = 7" in said and "set servo_id to 1 or 2" in said
    dome = tmp_path / "dome.toml"
    dome.write_text((CONFIGS / "emulated_nab_rti_v1.toml").read_text() + FAULT)
    r = runner.invoke(app, ["check", str(dome)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "overload with servo_id is a servo's fault" in said
    # the chain's power lost is the servos' too: it had reached the user as a traceback
    dome.write_text(
        (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
        + '\n[[emulator.faults]]\nat_command = 5\nkind = "power_lost"\n'
    )
    r = runner.invoke(app, ["check", str(dome)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "Traceback" not in said, said
    assert "emulator.faults[0]: power_lost is the servo chain's fault" in said, said
    # and on an arm, a servo_id is not said to pick whose status packet is lost
    power = '\n[[emulator.faults]]\nat_command = 5\nkind = "power_lost"\nservo_id = 1\n'
    r = runner.invoke(app, ["check", str(_config(tmp_path, power))], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "a power_lost silences every servo of the chain; remove servo_id" in said, said


def test_two_servos_faulting_at_one_packet_are_both_rehearsed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two ``[[emulator.faults]]`` at the same packet, one per servo (a supply sag overloads
    both joints at once): both servos latch their errors. The emulator kept its hardware
    faults by packet, one each, so the first was dropped without a word and only servo 2
    faulted."""
    emulators = emulators_built_by_check(monkeypatch)
    both = FAULT.replace("servo_id = 2", "servo_id = 1") + FAULT
    r = runner.invoke(app, ["check", str(_config(tmp_path, both))], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "Traceback" not in said, said
    (emu,) = emulators
    for dxl_id in (1, 2):
        assert emu.servos[dxl_id].get(ct.HARDWARE_ERROR_STATUS) & ct.HardwareFault.OVERLOAD


def test_the_configs_hardware_fault_kinds_are_the_emulators() -> None:
    """The kinds a config accepts as a servo's hardware error are those the emulator raises
    (two lists, in two layers: a kind added to one alone would be refused or never raised)."""
    from rti_rig.app.config import ARM_HARDWARE_FAULTS
    from rti_rig.simulator.dynamixel_emulator import HARDWARE_FAULT_BITS

    assert set(ARM_HARDWARE_FAULTS) == set(HARDWARE_FAULT_BITS)
