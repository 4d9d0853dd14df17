"""An emulated servo's powered state, as kept between two rti-rig commands.

A powered servo keeps its RAM and EEPROM and, with torque on, runs its profile to its Goal
Position; a limp loaded joint falls to its stop (ROBOTIS e-manual, X-series control table,
Area; Torque Enable (64)). The next command's servo takes up that state, at the end of the
motion; a record that is not that servo's is met as a power-cycled servo, never an error."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel import protocol2 as p2
from rti_rig.simulator.dynamixel_emulator import EmulatedServo
from rti_rig.simulator.servo_latch import STATE_DIR_ENV, LatchedErrors


def _moving(clock: VirtualClock) -> EmulatedServo:
    servo = EmulatedServo(1, 1060, clock, present_ticks=1000)
    assert servo.write(ct.PROFILE_VELOCITY.address, (20).to_bytes(4, "little")) == 0
    assert servo.write(ct.TORQUE_ENABLE.address, b"\x01") == 0
    assert servo.write(ct.GOAL_POSITION.address, (3000).to_bytes(4, "little")) == 0
    clock.sleep(0.1)
    assert servo.is_moving()
    return servo


def test_a_holding_servo_is_taken_up_at_its_goal_with_torque_on() -> None:
    clock = VirtualClock()
    state = _moving(clock).powered_state()
    fresh = EmulatedServo(1, 1060, VirtualClock(), present_ticks=2048)
    assert fresh.restore_powered(state)
    assert fresh.get(ct.TORQUE_ENABLE) == 1
    assert fresh.get(ct.PROFILE_VELOCITY) == 20
    assert round(fresh.position()) == 3000 and not fresh.is_moving()
    _, raw = fresh.read(ct.PRESENT_POSITION.address, 4)
    assert int.from_bytes(raw, "little") == 3000
    # EEPROM locked under the kept torque, as on the servo
    assert fresh.write(ct.MAX_POSITION_LIMIT.address, (4000).to_bytes(4, "little")) == (
        p2.ERR_ACCESS
    )


def test_a_record_of_another_servo_leaves_it_as_at_power_on() -> None:
    clock = VirtualClock()
    state = _moving(clock).powered_state()
    other_model = EmulatedServo(1, 1020, VirtualClock())
    assert not other_model.restore_powered(state)
    other_id = EmulatedServo(2, 1060, VirtualClock())
    assert not other_id.restore_powered(state)
    damaged = EmulatedServo(1, 1060, VirtualClock())
    assert not damaged.restore_powered({**state, "table": "zz"})
    assert not damaged.restore_powered({"table": state["table"]})
    for servo in (other_model, other_id, damaged):
        assert servo.get(ct.TORQUE_ENABLE) == 0


def test_an_eeprom_file_that_cannot_be_written_is_named_in_its_warning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each of the two state files is written by one writer, and a failure names the file that
    failed and what it held: the EEPROM file's had been said to be the powered state's file,
    which was written."""
    monkeypatch.setenv(STATE_DIR_ENV, str(tmp_path))
    latch = LatchedErrors(tmp_path / "arm.toml")
    latch.eeprom_path.mkdir(parents=True)  # a folder where the file goes: it cannot replace it
    states = {1: EmulatedServo(1, 1060, VirtualClock()).powered_state()}
    latch.save_state(states)
    with pytest.warns(RuntimeWarning) as caught:
        latch.save_eeprom(states)
    said = str(caught[0].message)
    assert f"EEPROM area and rest pose could not be kept in {latch.eeprom_path} (" in said, said
    assert str(latch.path) not in said, said
    assert latch.load_state() == states  # the powered state's file, written as before
    assert json.loads(latch.path.read_text())["hardware_error_status"] == {}


def test_two_servos_sharing_an_id_are_both_kept(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The second servo of a chain whose ID was written to the first's (both answer at 1) is
    kept too, its ID and its latched overload with it: the state had been kept by ID, and the
    second servo met the next command at power-on, at its old ID with no error."""
    from rti_rig.simulator import dynamixel_table as tbl
    from rti_rig.simulator.dynamixel_emulator import HARDWARE_FAULT_BITS, DynamixelBusEmulator

    monkeypatch.setenv(STATE_DIR_ENV, str(tmp_path))
    overload = int(HARDWARE_FAULT_BITS["overload"])
    chain = [EmulatedServo(1, 1060, VirtualClock()), EmulatedServo(2, 1060, VirtualClock())]
    assert chain[1].write(tbl.ID.address, b"\x01") == 0
    chain[1].inject_hardware_error(overload)
    latch = LatchedErrors(tmp_path / "arm.toml")
    latch.save_state(DynamixelBusEmulator(chain, VirtualClock()).powered_state())
    assert json.loads(latch.path.read_text())["hardware_error_status"] == {"1": overload}
    fresh = [EmulatedServo(1, 1060, VirtualClock()), EmulatedServo(2, 1060, VirtualClock())]
    bus = DynamixelBusEmulator(fresh, VirtualClock())
    bus.restore_powered(latch.load_state())
    assert [s.dxl_id for s in fresh] == [1, 1]
    assert [s.hardware_error for s in fresh] == [0, overload]
    assert list(bus.servos) == [1] and bus.servos[1] is fresh[0]
