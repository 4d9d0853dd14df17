"""A resume whose arm cannot be connected (a servo reporting an overload as the port opens)
says only what this run did: nothing was commanded.

It had said "Nothing was commanded: the arm could not be connected" and, in the same output,
"teardown problem: stop: … stop incomplete: servo 1 (azimuth) held where it is; elevation: …
(the arm may sag)": the previous run's teardown, read from the manifest that this run, never
begun, had not rewritten. Its own teardown had also tried to park the arm it never reached
("park: not connected; call connect() first"). An overloaded XL430 has switched its own
torque off (Shutdown (63) selects overload; ROBOTIS e-manual), so "held" was doubly false.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import emulators_built_by_check, inprocess_arm_config, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel import protocol2 as p2

runner = CliRunner()


def test_a_resume_whose_arm_overloads_at_connect_claims_no_stop_of_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # a first run: servo 2 overloads mid-run, after images were kept; its teardown's stop
    # fails on the limp servo (the manifest records "servo 1 (azimuth) held where it is")
    first = tmp_path / "first"
    first.mkdir()
    out = tmp_path / "s"
    cfg = inprocess_arm_config(first, servo_fault(200, 2))
    r = runner.invoke(
        app, ["run", str(cfg), "--out", str(out), "--lights", "6"], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "held where it is" in said, said
    assert "image(s) kept" in said, said  # a session to resume
    manifest = (out / "manifest.json").read_bytes()

    # the resume: servo 1 reports an overload at the first packet (torque off, its own rule)
    emulators = emulators_built_by_check(monkeypatch)
    again = tmp_path / "again"
    again.mkdir()
    cfg = inprocess_arm_config(again, servo_fault(1, 1))
    r = runner.invoke(app, ["run", str(cfg), "--resume", str(out)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "Traceback" not in said
    assert "Nothing was commanded: the arm could not be connected" in said, said
    assert "servo 1: hardware fault overload" in said and "Its torque is off" in said, said
    # no teardown problem of this run (none failed), none of the run before, no park of it
    assert "teardown problem" not in said, said
    assert "held where it is" not in said and "park" not in said, said
    # the config the user gave is in the command to continue with (it had been left out: the
    # resume would take the manifest's config, not the one chosen)
    assert f"Continue with: rti-rig run {cfg} --resume {out}" in said, said
    assert (out / "manifest.json").read_bytes() == manifest  # nothing of the session changed
    # the truth: nothing was written to a servo, and servo 1 is limp by its own shutdown
    (emu,) = emulators
    assert not [p for p in emu.instructions if p.instruction == p2.INST_WRITE]
    assert emu.goal_log == []
    assert emu.servos[1].get(ct.TORQUE_ENABLE) == 0
