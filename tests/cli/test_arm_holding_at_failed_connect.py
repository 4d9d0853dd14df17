"""An arm an earlier command left holding the lamp (torque on, away from its park pose) whose
next connect fails before writing anything is said to be still powered and holding it.

A servo keeps Torque Enable (64) while powered (RAM is reset only at power-on: ROBOTIS
e-manual, X-series control table), and the emulated chain keeps it between commands
(:mod:`rti_rig.simulator.servo_latch`). The failed connect had been said as "nothing was
commanded: the arm could not be connected" and "NOT parked", with no word that the lamp still
hung there under torque: a user reaching in to fix the cabling met a live arm."""

from __future__ import annotations

from pathlib import Path

from conftest import inprocess_arm_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _drops(first: int, last: int) -> str:
    return "".join(
        f'\n[[emulator.faults]]\nat_command = {n}\nkind = "drop_reply"\n'
        for n in range(first, last + 1)
    )


def _left_holding(tmp_path: Path) -> Path:
    """The in-process emulated arm after a check that left it holding, unparked."""
    cfg = inprocess_arm_config(tmp_path)
    text = cfg.read_text().replace(
        'transport = "inprocess"', 'transport = "inprocess"\npark_after_session = false'
    )
    cfg.write_text(text)
    r = runner.invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "left at az 169.5°, el 37.5° (read back)" in said, said
    return cfg


def test_a_failed_connect_says_the_arm_still_holds_the_lamp(tmp_path: Path) -> None:
    cfg = _left_holding(tmp_path)
    cfg.write_text(cfg.read_text() + _drops(1, 6))  # the chain silent to the connect's pings
    r = runner.invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "RESULT: FAIL" in said, said
    assert "nothing was commanded: the arm could not be connected; but the arm is still " in said
    assert (
        "powered and holding the lamp at az 169.5°, el 37.5° (read back, away from its park "
        "pose): servo 1 (azimuth), servo 2 (elevation) read Torque Enable ON" in said
    ), said
    assert "support the lamp before touching the arm" in said, said
    # the session command says it too (its stop's sentence), and captures nothing
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "but the arm is still powered and holding the lamp at az 169.5°, el 37.5°" in said
    assert not out.exists()


def test_a_torque_that_could_not_be_read_is_said_unknown_never_off(tmp_path: Path) -> None:
    cfg = _left_holding(tmp_path)
    cfg.write_text(cfg.read_text() + _drops(1, 80))  # silent to every packet of the connect
    r = runner.invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert "whether the arm is still holding the lamp under torque is not known" in said, said
    assert "treat the arm as powered" in said and "read its torque off" not in said, said
