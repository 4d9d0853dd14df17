"""A servo's hardware error outlives the command that met it, as on a powered servo.

A real X-series servo keeps its Hardware Error Status (70) until a Reboot or a power-off
(ROBOTIS e-manual, Shutdown (63): after a shutdown only a Reboot re-enables torque). Each
rti-rig command built a fresh emulator, so after a run stopped by an overload on the shipped
emulated arm the documented recovery, ``rti-rig check ARM.toml --reboot-faulted``, said
"no hardware fault: not rebooted": the recovery could not be rehearsed. The emulated chain is
now kept powered between commands (its latched errors in a small state file per config).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import inprocess_arm_config, journal, said, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.simulator.servo_latch import STATE_DIR_ENV

runner = CliRunner()

# the elevation servo overloads part-way through the run, once some images are kept
FAULT = servo_fault(200, 2)


def test_a_faulted_run_is_recovered_by_reboot_faulted_then_resumed(tmp_path: Path) -> None:
    cfg = inprocess_arm_config(tmp_path, FAULT)
    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(cfg), "--lights", "6", "--out", str(out)], terminal_width=400
    )
    words = said(r)
    assert r.exit_code == 2 and "Traceback" not in words, words
    assert "servo 2: hardware fault overload" in words, words
    assert "found already set" not in words, words  # met mid-run: this run's own fault
    assert "Its torque is off (as read after the fault)" in words, words
    kept = len(journal(out))
    assert 0 < kept < 6, words

    # the servo is still faulted for the next command: the resume meets it as the port opens
    r = runner.invoke(app, ["run", "--resume", str(out)], terminal_width=400)
    words = said(r)
    assert r.exit_code != 0 and "Traceback" not in words, words
    assert "arm during 'connect': servo 2: hardware fault overload" in words, words
    # said as one found at connect, left by an earlier command, not as this one's doing
    assert (
        "(Hardware Error Status 0x20) found already set as the arm connected, before this "
        "command drove it: a servo keeps its fault until it is rebooted or powered off, so it "
        "may date from an earlier session" in words
    ), words
    assert "Its torque is off (as read at connect)" in words, words
    assert "Nothing was commanded: the arm could not be connected" in words, words
    # the azimuth servo still holds, the faulted elevation one is limp: not "holding the lamp"
    assert "still powered and only partly holding the lamp" in words, words
    assert "servo 2 (elevation) read it off: that joint is limp, and the lamp's weight" in words
    assert "still powered and holding the lamp" not in words, words
    # where it is, read past the faulted servo's Alert bit (it had been "could not be read")
    assert "only partly holding the lamp at az " in words, words
    assert "(read back, away from its park pose)" in words, words
    assert len(journal(out)) == kept

    # the documented recovery reboots the faulted servo, and it is cleared for good
    r = runner.invoke(app, ["check", str(cfg), "--reboot-faulted"], terminal_width=400)
    words = said(r)
    assert r.exit_code == 0 and "Traceback" not in words, words
    assert "servo 1 (azimuth): no hardware fault (Hardware Error Status 0x00): not rebooted" in (
        words
    )
    assert (
        "servo 2 (elevation): hardware fault overload (0x20); rebooted, Hardware Error Status "
        "read back 0x00" in words
    ), words
    assert words.endswith("RESULT: PASS"), words
    r = runner.invoke(app, ["check", str(cfg), "--reboot-faulted"], terminal_width=400)
    assert "nothing rebooted" in said(r) and r.exit_code == 0, said(r)

    # the obstruction cleared (the rehearsed fault taken out of the config): the resume ends
    cfg.write_text(cfg.read_text().replace(FAULT, ""))
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"], terminal_width=400)
    words = said(r)
    assert r.exit_code == 0 and "Traceback" not in words, words
    assert len(journal(out)) == 6, words


def test_each_config_has_its_own_chain(tmp_path: Path) -> None:
    """Another config (another path) is another rig: its servos meet no other's error."""
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    faulted = inprocess_arm_config(tmp_path / "a", FAULT)
    r = runner.invoke(
        app,
        ["run", str(faulted), "--lights", "6", "--out", str(tmp_path / "s")],
        terminal_width=400,
    )
    assert "servo 2: hardware fault overload" in said(r), said(r)
    other = inprocess_arm_config(tmp_path / "b")
    r = runner.invoke(app, ["check", str(other), "--reboot-faulted"], terminal_width=400)
    assert "nothing rebooted" in said(r) and r.exit_code == 0, said(r)


def test_a_state_file_that_cannot_be_written_leaves_the_servo_fault_said(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A state folder that cannot be made (a full disk, another user's folder in the shared
    temp folder) is a warning: the run still ends on the servo's own fault, not on its port.

    The state is written from inside the emulated bus as a status goes out, so the OSError had
    reached the driver as "the port 'inprocess' failed …: check that the arm's USB adapter
    (e.g. a U2D2) is still plugged in", the overload said only among the teardown problems."""
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setenv(STATE_DIR_ENV, str(blocker / "servo-state"))
    cfg = inprocess_arm_config(tmp_path, FAULT)
    # each of the two state files warned of on its own (the EEPROM's had repeated the other's)
    unkept = "could not be kept in .*(as if power-cycled|met factory-fresh)"
    with pytest.warns(RuntimeWarning, match=unkept) as caught:
        r = runner.invoke(
            app,
            ["run", str(cfg), "--lights", "6", "--out", str(tmp_path / "s")],
            terminal_width=400,
        )
    warned = {str(w.message) for w in caught}
    assert any("powered state" in w and ".eeprom.json" not in w for w in warned), warned
    assert any("EEPROM area" in w and ".eeprom.json (" in w for w in warned), warned
    words = said(r)
    assert r.exit_code == 2 and "Traceback" not in words, words
    assert "USB adapter" not in words, words
    assert "error: arm during 'move to az" in words, words
    assert "servo 2: hardware fault overload" in words.split("error: ")[-1], words


def test_the_obstruction_cleared_first_leaves_the_fault_for_the_reboot(tmp_path: Path) -> None:
    """The error's advice in its own order: "clear the obstruction; then run rti-rig check …
    --reboot-faulted". On the emulated arm the obstruction is cleared by taking the rehearsed
    fault out of the config; the servo's latched error is still there for the reboot, as on a
    real servo (the chain had been keyed by the config's [emulator] section too, so the edit
    met a fresh chain: "no hardware fault: not rebooted", the recovery not rehearsed)."""
    cfg = inprocess_arm_config(tmp_path, FAULT)
    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(cfg), "--lights", "6", "--out", str(out)], terminal_width=400
    )
    assert "servo 2: hardware fault overload" in said(r), said(r)
    cfg.write_text(cfg.read_text().replace(FAULT, ""))
    r = runner.invoke(app, ["check", str(cfg), "--reboot-faulted"], terminal_width=400)
    words = said(r)
    assert r.exit_code == 0 and "Traceback" not in words, words
    assert (
        "servo 2 (elevation): hardware fault overload (0x20); rebooted, Hardware Error Status "
        "read back 0x00" in words
    ), words
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"], terminal_width=400)
    assert r.exit_code == 0 and len(journal(out)) == 6, said(r)
