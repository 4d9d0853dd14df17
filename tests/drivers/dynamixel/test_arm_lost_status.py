"""A status packet lost or damaged on the wire, to a write: retried once, through the CLI.

One lost reply to a lamp, goal or settings write had ended a check or a session with
COMM_RX_TIMEOUT, though the servo had acted on the write; a write of a register's value is
idempotent, so it is sent once more (as reads were). The shipped arm config rehearses it with
``[[emulator.faults]]``, which an arm config had silently ignored."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.drivers.dynamixel import protocol2 as p2

runner = CliRunner()


def _arm_config(tmp_path: Path, faults: str) -> Path:
    text = (CONFIGS / "simulated_arm.toml").read_text()
    text = text.replace('transport = "pty"', 'transport = "inprocess"')
    path = tmp_path / "arm.toml"
    path.write_text(text + "\n[emulator]\n" + faults)
    return path


def _writes(config: Path, upto: int) -> list[int]:
    """The 1-based numbers of the write instructions among the first ``upto`` the emulated
    servos receive during a clean check of ``config`` (what a fault's at_command counts)."""
    clean = config.with_name("clean.toml")
    clean.write_text(config.read_text().split("\n[emulator]\n")[0])
    with build_rig(load_rig_config(clean)) as rig:
        carrier = rig.lighting.carrier  # type: ignore[attr-defined]
        carrier.connect()
        carrier.lamp(True)
        carrier.lamp(False)
        carrier.close()
        sent = rig.emulator.instructions  # type: ignore[attr-defined]
    return [i + 1 for i, pkt in enumerate(sent[:upto]) if pkt.instruction == p2.INST_WRITE]


@pytest.mark.parametrize("kind", ["drop_reply", "garble_reply"])
def test_a_lost_or_damaged_status_to_a_write_is_retried_and_the_check_passes(
    tmp_path: Path, kind: str
) -> None:
    probe = _arm_config(tmp_path, "")
    writes = _writes(probe, 60)
    assert len(writes) >= 3, writes
    # the connect's first write (a settings write), and two later ones (torque, lamp)
    faults = "".join(
        f'[[emulator.faults]]\nat_command = {k}\nkind = "{kind}"\n'
        for k in (writes[0], writes[len(writes) // 2], writes[-1])
    )
    cfg = _arm_config(tmp_path, faults)
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 0, r.output
    assert "RESULT: PASS" in r.output and "COMM_RX" not in r.output, r.output


def test_a_write_whose_status_is_lost_twice_is_a_named_error(tmp_path: Path) -> None:
    """Lost on the retry too: the servo (or its cable) is not answering, said as before."""
    writes = _writes(_arm_config(tmp_path, ""), 60)
    first = writes[0]
    faults = "".join(
        f'[[emulator.faults]]\nat_command = {k}\nkind = "drop_reply"\n' for k in (first, first + 1)
    )
    r = runner.invoke(app, ["check", str(_arm_config(tmp_path, faults))], terminal_width=400)
    assert r.exit_code == 1, r.output
    assert "COMM_RX_TIMEOUT" in r.output and "servo 1" in r.output, r.output


def test_an_arm_fault_the_servo_bus_cannot_rehearse_is_refused_naming_the_key(
    tmp_path: Path,
) -> None:
    cfg = _arm_config(tmp_path, '[[emulator.faults]]\nat_command = 5\nkind = "reset"\n')
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 2, r.output
    assert "emulator.faults[0].kind = 'reset'" in r.output, r.output
    assert "drop_reply, garble_reply" in r.output and "overload" in r.output


def test_a_slow_links_advice_names_the_adapters_own_latency_timer(tmp_path: Path) -> None:
    """The latency timer is named with the file of the port's own adapter, ready to paste
    (through a by-id link, as a config names the port); a port with none (a pty) is given no
    command, never a template."""
    from rti_rig.drivers.dynamixel.bus import _latency_note

    tty = tmp_path / "dev" / "ttyUSB3"
    tty.parent.mkdir()
    tty.touch()
    link = tmp_path / "usb-FTDI_U2D2-if00-port0"
    link.symlink_to(tty)
    devices = tmp_path / "sys devices"
    (devices / "ttyUSB3").mkdir(parents=True)
    (devices / "ttyUSB3" / "latency_timer").write_text("16\n")
    timer = devices / "ttyUSB3" / "latency_timer"
    assert _latency_note(str(link), str(devices)) == (
        f" (set its latency timer to 1 ms: echo 1 | sudo tee '{timer}')"
    )
    assert _latency_note(str(tmp_path / "pts3"), str(devices)) == ""


def test_a_late_status_is_not_said_of_a_later_command_that_gets_none() -> None:
    """A read whose statuses came too late is said as a slow link; a reboot sent after it,
    whose status is lost, is not (the mark had stayed on the servo's id: a servo gone since
    would have been called there, only slow)."""
    from rti_rig.core.clock import VirtualClock
    from rti_rig.drivers.dynamixel import control_table as ct
    from rti_rig.drivers.dynamixel.bus import DxlBus
    from rti_rig.drivers.dynamixel.faults import CommunicationError
    from rti_rig.simulator.dynamixel_emulator import (
        DynamixelBusEmulator,
        EmulatedServo,
        InProcessPort,
    )

    emu = DynamixelBusEmulator([EmulatedServo(1, 1060, VirtualClock())], VirtualClock())
    bus = DxlBus(InProcessPort(emu), "arm")
    bus.open(57600)
    assert bus.ping(1) == 1060
    for k in (1, 2):  # the read and its retry
        emu.add_fault(emu.instructions_received + k, "delay_reply", delay_s=2.0)
    with pytest.raises(CommunicationError, match="but late"):
        bus.read(1, ct.PRESENT_POSITION)
    bus.drain_reply()
    emu.add_fault(emu.instructions_received + 1, "drop_reply")
    with pytest.raises(CommunicationError) as lost:
        bus.reboot(1)
    assert "late" not in str(lost.value), lost.value


def test_after_a_silent_servo_a_slow_but_live_one_keeps_the_slow_links_allowance() -> None:
    """A servo found silent through a whole patient wait marks the link silent, and the next
    silent servo gets the SDK's window alone (a chain without power); but a servo whose
    statuses come late on that link is still waited for, its late status counted as such, and
    one that never answers in time is still said to be there but slow, not a lost cable."""
    from rti_rig.core.clock import VirtualClock
    from rti_rig.drivers.dynamixel import control_table as ct
    from rti_rig.drivers.dynamixel.bus import PATIENT_REPLY_MS, DxlBus
    from rti_rig.drivers.dynamixel.faults import CommunicationError
    from rti_rig.simulator.dynamixel_emulator import (
        DynamixelBusEmulator,
        EmulatedServo,
        InProcessPort,
    )

    clock = VirtualClock()
    emu = DynamixelBusEmulator([EmulatedServo(i, 1060, clock) for i in (1, 2, 3)], clock)
    port = InProcessPort(emu)
    bus = DxlBus(port, "arm")
    bus.open(57600)
    for i in (1, 2, 3):
        bus.ping(i)
    emu.silent_ids.add(1)  # its cable alone pulled
    before = clock.now()
    with pytest.raises(CommunicationError, match="has stopped answering"):
        bus.read(1, ct.PRESENT_POSITION)
    assert (clock.now() - before) * 1000 > 2 * PATIENT_REPLY_MS  # the allowance, once
    assert bus.link_silent
    emu.add_fault(emu.instructions_received + 1, "delay_reply", delay_s=0.2)
    assert bus.read(2, ct.TORQUE_ENABLE) in (0, 1)  # late, waited for, answered
    assert not bus.link_silent and bus.resent == ["id 2 read Torque Enable: late status packet"]
    with pytest.raises(CommunicationError, match="has stopped answering"):
        bus.read(1, ct.PRESENT_POSITION)
    assert bus.link_silent
    emu.add_fault(emu.instructions_received + 1, "drop_reply")  # a status lost, not late
    assert bus.read(3, ct.TORQUE_ENABLE) in (0, 1)  # its retry answered: the link lives
    assert not bus.link_silent and bus.resent[-1] == "id 3 read Torque Enable: no status packet"
    with pytest.raises(CommunicationError, match="has stopped answering"):
        bus.read(1, ct.PRESENT_POSITION)
    for k in (1, 2):  # the read and its retry, both late
        emu.add_fault(emu.instructions_received + k, "delay_reply", delay_s=2.0)
    with pytest.raises(CommunicationError, match="but late"):
        bus.read(3, ct.PRESENT_POSITION)


@pytest.mark.parametrize(("damage", "silent"), [("corrupt", False), ("drop", True)])
def test_a_stop_tells_a_damaged_status_from_silence_by_the_bus_result(
    damage: str, silent: bool
) -> None:
    """Statuses that come with a bad CRC (COMM_RX_CORRUPT) came from a powered servo; only
    none at all (COMM_RX_TIMEOUT) is said as silence, "unpowered, it is limp". Told by the
    error's result code, which it carries: it had been found in the message's words."""
    import dynamixel_sdk as sdk

    from rti_rig.core.clock import VirtualClock
    from rti_rig.drivers.dynamixel.arm import DynamixelArm
    from rti_rig.drivers.dynamixel.bus import no_reply
    from rti_rig.drivers.dynamixel.faults import StopIncompleteError
    from rti_rig.drivers.dynamixel.settings import ArmSettings
    from rti_rig.simulator.dynamixel_emulator import InProcessPort, emulator_for_arm

    table = tomllib.loads((CONFIGS / "simulated_arm.toml").read_text())
    settings = ArmSettings.model_validate(table["arm"]["dynamixel"])
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    arm = DynamixelArm(settings, InProcessPort(emu), clock)
    arm.connect()
    setattr(emu, f"{damage}_next_replies", 10_000)  # every status from now on
    with pytest.raises(StopIncompleteError) as stop:
        arm.stop()
    assert stop.value.unheld and all(j.no_reply is silent for j in stop.value.unheld)
    cause = stop.value.__cause__
    expected = sdk.COMM_RX_TIMEOUT if silent else sdk.COMM_RX_CORRUPT
    assert getattr(cause, "result", None) == expected and no_reply(cause) is silent
    assert ("— no reply: unpowered" in str(stop.value)) is silent, stop.value
