"""A servo fault's advice names the rig config in the ``--reboot-faulted`` command it gives.

``run`` and ``check`` had said "then run rti-rig check RIG.toml --reboot-faulted" of a config
they had just opened: a placeholder the user had to replace. The command now names the config
(shell-quoted), and pasted as it is said it clears the fault.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
from conftest import emulators_built_by_check, inprocess_arm_config, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.dynamixel import control_table as ct

runner = CliRunner()

# servo 2 already overloaded as rti-rig opens the port (its torque off by its own Shutdown)
FAULT = servo_fault(1, 2)


def _advised(said: str) -> list[str]:
    """The arguments of the ``rti-rig check … --reboot-faulted`` command in ``said``."""
    found = re.search(r"then run rti-rig (check .+? --reboot-faulted) \(it reboots", said)
    assert found, said
    return shlex.split(found.group(1))


@pytest.mark.parametrize("command", ["check", "run"])
def test_the_advised_reboot_command_names_the_config_and_clears_the_fault(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, command: str
) -> None:
    folder = tmp_path / "my rigs"  # a space: the path must be quoted to be pasted
    folder.mkdir()
    cfg = inprocess_arm_config(folder, FAULT)
    args = [command, str(cfg)] + (["--out", str(tmp_path / "s")] if command == "run" else [])
    r = runner.invoke(app, args, terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code in (1, 2) and "servo 2: hardware fault overload" in said, said
    assert "RIG.toml" not in said, said
    assert f"then run rti-rig check {shlex.quote(str(cfg))} --reboot-faulted" in said, said

    # pasted as said: it reboots the faulted servo (a config with the same fault raised at
    # the first packet, as the servo still reports it), and the fault is cleared
    emulators = emulators_built_by_check(monkeypatch)
    r = runner.invoke(app, _advised(said), terminal_width=400)
    again = " ".join(r.output.split())
    assert r.exit_code == 0, again
    assert "servo 2 (elevation): hardware fault overload (0x20); rebooted" in again, again
    (emu,) = emulators
    assert emu.servos[2].get(ct.HARDWARE_ERROR_STATUS) == 0


def test_an_emulated_arms_power_cycle_is_advised_as_what_clears_it(tmp_path: Path) -> None:
    """An emulated chain has no power switch: its latched errors outlive a command in a state
    file (:mod:`rti_rig.simulator.servo_latch`), and the advice's power cycle is deleting that
    file, named so that it can be pasted. "switch the servos' power off and on" had been said
    of it, which no one could do."""
    cfg = inprocess_arm_config(tmp_path, FAULT)
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "servo 2: hardware fault overload" in said, said
    assert "switch the servos' power" not in said, said
    found = re.search(r"--reboot-faulted \(it reboots .+?\), or delete (.+?) \(where the", said)
    assert found, said
    (state,) = shlex.split(found.group(1))
    assert Path(state).is_file()

    cfg.write_text(cfg.read_text().replace(FAULT, ""))  # the obstruction cleared
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 1 and "hardware fault overload" in " ".join(r.output.split())  # kept

    Path(state).unlink()  # as advised
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    again = " ".join(r.output.split())
    assert r.exit_code == 0 and "RESULT: PASS" in again, again
