"""The emulated arm's servos stay powered between two commands, as a real chain does.

A powered X-series servo keeps its RAM (Torque Enable, Goal Position, …) until a power cycle or
a Reboot (ROBOTIS e-manual, X-series control table, Area), and its EEPROM area is writable
only with Torque Enable 0 ("Data in the EEPROM Area can only be written when the value of
Torque Enable(64) is cleared to '0'"). The emulated chain had kept only its latched errors:
each command met servos limp at the park pose, so a session that left torque on
(``release_on_close`` away from park, ``hold``) was never followed by what a real arm meets,
and the input-voltage advice "--reboot-faulted will not reboot it" was false on it. Its state
file (:mod:`rti_rig.simulator.servo_latch`) now keeps the servos' control tables and poses;
deleting it, as advised, is its power cycle.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path
from typing import Any

import pytest
from conftest import emulators_built_by_check, inprocess_arm_config, said, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel import protocol2 as p2

runner = CliRunner()

RELEASE = ('torque_policy = "hold"', 'torque_policy = "release_on_close"')


def _left_holding(tmp_path: Path) -> Path:
    """A config whose run leaves the arm away from park with its torque on:
    ``release_on_close`` releases only at the park pose, and ``park_after_session`` is off."""
    cfg = inprocess_arm_config(tmp_path)
    text = cfg.read_text()
    assert RELEASE[0] in text and "\n[arm]\n" in text
    cfg.write_text(
        text.replace(*RELEASE).replace("\n[arm]\n", "\n[arm]\npark_after_session = false\n", 1)
    )
    return cfg


def _servos_as_built(monkeypatch: pytest.MonkeyPatch) -> list[dict[int, tuple[int, int]]]:
    """Each command's servos as it finds them, before it sends anything: (Torque Enable,
    Present Position) by id."""
    import rti_rig.app.compose as compose

    found: list[dict[int, tuple[int, int]]] = []
    real = compose._keep_powered_state

    def keep(loaded: Any, emulator: Any) -> Any:
        latch = real(loaded, emulator)
        found.append(
            {i: (s.get(ct.TORQUE_ENABLE), round(s.position())) for i, s in emulator.servos.items()}
        )
        return latch

    monkeypatch.setattr(compose, "_keep_powered_state", keep)
    return found


def _run_left_holding(
    tmp_path: Path, cfg: Path, monkeypatch: pytest.MonkeyPatch
) -> dict[int, tuple[int, int]]:
    """``run --lights 6`` on ``cfg``; the servos' (Torque Enable, position) as it left them."""
    emulators = emulators_built_by_check(monkeypatch)
    r = runner.invoke(
        app,
        ["run", str(cfg), "--lights", "6", "--out", str(tmp_path / "s"), "--no-verdict"],
        terminal_width=400,
    )
    words = said(r)
    assert r.exit_code == 0 and "Traceback" not in words, words
    assert "torque stays on: the arm is not at its park pose" in words, words
    (emu,) = emulators
    left = {i: (s.get(ct.TORQUE_ENABLE), round(s.position())) for i, s in emu.servos.items()}
    assert all(torque == 1 for torque, _ in left.values()), left
    return left


def test_the_next_command_finds_the_arm_holding_where_the_session_left_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = _left_holding(tmp_path)
    found = _servos_as_built(monkeypatch)
    left = _run_left_holding(tmp_path, cfg, monkeypatch)
    park = found[0]  # the first command met a fresh chain: limp, at the park pose
    assert all(torque == 0 for torque, _ in park.values()), park
    assert left != park

    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    words = said(r)
    # a powered chain: torque still on, the joints where the run left them (within a tick of
    # rounding), and the connect on that holding arm passes (its limits already written)
    assert found[1] == left, (found[1], left)
    assert r.exit_code == 0 and words.endswith("RESULT: PASS"), words


def test_limits_changed_under_a_holding_arm_away_from_park_are_refused_before_any_write(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The limits are EEPROM: written torque off. Away from park, that torque-off drops the
    lamp; the connect had sent it without a word. Now nothing is written, and the advice (the
    emulated chain's power cycle: delete its state file) lets the check pass after it."""
    cfg = _left_holding(tmp_path)
    left = _run_left_holding(tmp_path, cfg, monkeypatch)
    text = cfg.read_text()
    assert "max_deg = 90.0" in text
    cfg.write_text(text.replace("max_deg = 90.0", "max_deg = 85.0"))

    emulators = emulators_built_by_check(monkeypatch)
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    words = said(r)
    assert r.exit_code != 0 and "Traceback" not in words, words
    assert (
        "the elevation servo's Min/Max Position Limit are 1024..2048 but the config gives "
        "1024..1991, and writing them (EEPROM) needs its torque off, while servo 2 (elevation) "
        "holds the arm away from its park pose (Torque Enable read back ON" in words
    ), words
    assert "Nothing was written" in words, words
    (emu,) = emulators  # the truth: no write reached a servo, both still hold, nothing fell
    assert not [p for p in emu.instructions if p.instruction == p2.INST_WRITE], emu.instructions
    assert all(s.get(ct.TORQUE_ENABLE) == 1 for s in emu.servos.values())
    assert emu.servos[2].get(ct.MAX_POSITION_LIMIT) == 2048
    assert {i: round(s.position()) for i, s in emu.servos.items()} == {
        i: ticks for i, (_, ticks) in left.items()
    }

    found = re.search(r"support the arm and delete (.+?) \(where the emulated", words)
    assert found, words
    (state,) = shlex.split(found.group(1))
    Path(state).unlink()  # as advised: the power cycle
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 0 and said(r).endswith("RESULT: PASS"), said(r)


def test_limits_changed_with_the_arm_held_at_park_are_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``hold`` keeps torque on at the park pose: there the torque-off for the EEPROM write is
    safe, and it is sent (a servo refuses an EEPROM write under torque: Access Error)."""
    cfg = inprocess_arm_config(tmp_path)
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 0, said(r)
    cfg.write_text(cfg.read_text().replace("max_deg = 90.0", "max_deg = 85.0"))
    found = _servos_as_built(monkeypatch)
    emulators = emulators_built_by_check(monkeypatch)
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    words = said(r)
    assert all(torque == 1 for torque, _ in found[0].values()), found  # held at park
    assert r.exit_code == 0 and words.endswith("RESULT: PASS"), words
    (emu,) = emulators
    assert emu.servos[2].get(ct.MAX_POSITION_LIMIT) == 1991


def test_an_input_voltage_fault_leaves_the_servo_holding_for_the_reboot_check(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The XL430's Shutdown (0x34) does not select an input-voltage error: the servo keeps
    its torque on, so ``--reboot-faulted`` leaves it alone, as the error's advice says. On
    the emulated chain it had found the servo limp (fresh) and rebooted it."""
    fault = servo_fault(200, 2, "input_voltage")
    cfg = inprocess_arm_config(tmp_path, fault)
    r = runner.invoke(
        app,
        ["run", str(cfg), "--lights", "6", "--out", str(tmp_path / "s"), "--no-verdict"],
        terminal_width=400,
    )
    words = said(r)
    assert r.exit_code == 2 and "servo 2: hardware fault input voltage" in words, words
    assert "--reboot-faulted will not reboot it" in words, words
    cfg.write_text(cfg.read_text().replace(fault, ""))  # the supply fixed

    emulators = emulators_built_by_check(monkeypatch)
    r = runner.invoke(app, ["check", str(cfg), "--reboot-faulted"], terminal_width=400)
    words = said(r)
    assert r.exit_code == 1 and "Traceback" not in words, words
    assert "servo 2 (elevation): hardware fault input voltage (0x01) but its torque is on" in (
        words
    ), words
    assert "nothing rebooted; no torque was switched on or off" in words, words
    (emu,) = emulators
    assert not [p for p in emu.instructions if p.instruction == p2.INST_REBOOT]
    assert emu.servos[2].get(ct.TORQUE_ENABLE) == 1

    found = re.search(r"support the arm and delete (.+?) \(where the emulated", words)
    assert found, words
    (state,) = shlex.split(found.group(1))
    Path(state).unlink()  # the power cycle the advice names clears the fault
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 0 and said(r).endswith("RESULT: PASS"), said(r)


def test_a_power_cycle_keeps_the_eeprom_and_where_the_joints_rest(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A power cycle resets the RAM area only ("reset to initial values when the power is
    reset"; the EEPROM area is not: ROBOTIS e-manual, X-series control table, Area), and a
    joint that held its load under torque falls to its stop as the power goes. The emulated
    chain's power cycle (deleting its state file) had reset the EEPROM too and put the joints
    back at the park pose: limits a connect wrote were gone, and a config set back to the old
    limits met servos that already had them (no write), as no real chain would."""
    from rti_rig.simulator.servo_latch import LatchedErrors

    cfg = inprocess_arm_config(tmp_path)
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 0, said(r)  # parked, held at park (torque_policy "hold")
    cfg.write_text(cfg.read_text().replace("max_deg = 90.0", "max_deg = 85.0"))
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 0, said(r)  # the elevation servo's Max Position Limit now 1991
    latch = LatchedErrors(cfg)
    latch.path.unlink()  # the power cycle, as the advice says
    assert latch.eeprom_path.exists()

    cfg.write_text(cfg.read_text().replace("max_deg = 85.0", "max_deg = 90.0"))
    found = _servos_as_built(monkeypatch)
    emulators = emulators_built_by_check(monkeypatch)
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    words = said(r)
    assert r.exit_code == 0 and words.endswith("RESULT: PASS"), words
    # RAM at power-on: torque off; azimuth where it held (the park pose, 0°: tick 2048), the
    # loaded elevation joint fallen from 10° to its stop at 0° (tick 1024)
    assert found[0] == {1: (0, 2048), 2: (0, 1024)}, found
    (emu,) = emulators
    limit_writes = [
        p
        for p in emu.instructions
        if p.instruction == p2.INST_WRITE
        and p.dxl_id == 2
        and p.params[:2] == ct.MAX_POSITION_LIMIT.address.to_bytes(2, "little")
    ]
    assert limit_writes, "the kept limit (1991) was not found to differ from the config's"
    assert emu.servos[2].get(ct.MAX_POSITION_LIMIT) == 2048

    # both files deleted: a factory-fresh chain as the config describes it, at the park pose
    latch.path.unlink()
    latch.eeprom_path.unlink()
    found.clear()
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 0, said(r)
    park_el = found[0][2][1]
    assert found[0][1] == (0, 2048) and park_el > 1024, found
