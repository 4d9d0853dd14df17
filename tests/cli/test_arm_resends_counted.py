"""A status packet lost or damaged on an emulated arm's bus, and asked again, is counted once at
the end of a run or a check, never printed as a raw log record.

Before, each retry was a WARNING record ("arm: id 2 read Velocity Limit: COMM_RX_TIMEOUT:
[TxRxResult] There is no status packet!; retrying once"), which the command line (configuring
no logging) printed raw on stderr in the middle of the progress bar.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

#: Commands 12 and 21 of the emulated chain: reads of the connect's limit checks (21: the
#: connect reads each servo's Torque Enable before switching it off to write the limits).
FAULTS = (
    '[[emulator.faults]]\nat_command = 12\nkind = "drop_reply"\n'
    '[[emulator.faults]]\nat_command = 21\nkind = "garble_reply"'
)
LINE = (
    "The arm's servos were asked again 2 times after a status packet was lost or damaged "
    "(1 lost status packet, 1 damaged status packet); each then answered."
)


def _config(tmp_path: Path, faults: str) -> Path:
    cfg = tmp_path / "rig.toml"
    cfg.write_text((CONFIGS / "simulated_arm.toml").read_text() + f"\n{faults}\n")
    return cfg


def _invoke(argv: list[str], caplog: pytest.LogCaptureFixture) -> tuple[object, str]:
    with caplog.at_level(logging.DEBUG):
        r = CliRunner().invoke(app, argv, terminal_width=400)
    said = " ".join(r.output.split())
    loud = [x.getMessage() for x in caplog.records if x.levelno >= logging.WARNING]
    assert not [m for m in loud if "retrying once" in m], loud
    for raw in ("retrying once", "COMM_RX_TIMEOUT", "COMM_RX_CORRUPT", "WARNING:"):
        assert raw not in said, (raw, said)
    return r, said


def test_a_run_counts_the_status_packets_asked_again_once_and_keeps_them(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    out = tmp_path / "S"
    argv = ["run", str(_config(tmp_path, FAULTS)), "--lights", "6", "--out", str(out)]
    r, said = _invoke([*argv, "--no-verdict"], caplog)
    assert r.exit_code == 0, said  # type: ignore[attr-defined]
    assert said.count(LINE) == 1, said
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert runner["arm_resent"] == [
        "id 2 read Velocity Limit: no status packet",
        "id 1 read Max Position Limit: damaged status packet",
    ]


def test_a_check_counts_them_in_its_report(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    r, said = _invoke(["check", str(_config(tmp_path, FAULTS))], caplog)
    assert r.exit_code == 0, said  # type: ignore[attr-defined]
    assert said.count(LINE) == 1 and said.index(LINE) < said.index("RESULT: PASS"), said


def test_a_clean_run_says_nothing_of_it(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    out = tmp_path / "S"
    argv = ["run", str(_config(tmp_path, "")), "--lights", "6", "--out", str(out)]
    r, said = _invoke([*argv, "--no-verdict"], caplog)
    assert r.exit_code == 0, said  # type: ignore[attr-defined]
    assert "asked again" not in said, said
    assert "arm_resent" not in json.loads((out / "manifest.json").read_text())["runner"]


def _late(at: int, delay_s: float) -> str:
    """The statuses of instruction packets ``at`` and ``at + 1`` (a command and its retry)
    ``delay_s`` late: a slow USB-serial adapter, or a host too loaded to read in time."""
    return "\n".join(
        f'[[emulator.faults]]\nat_command = {k}\nkind = "delay_reply"\ndelay_s = {delay_s}'
        for k in (at, at + 1)
    )


def test_a_status_late_past_the_sdks_window_is_waited_for_on_the_retry(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """Statuses 100 ms late (past the SDK's 34 ms window) to a command and to its retry: the
    retry had the same window, so the check aborted with "its cable … or the servos' power
    supply was lost" (what a loaded machine did to the pty emulator). The retry now waits
    PATIENT_REPLY_MS for it, and the status is counted as late, not lost."""
    r, said = _invoke(["check", str(_config(tmp_path, _late(12, 0.1)))], caplog)
    assert r.exit_code == 0, said  # type: ignore[attr-defined]
    assert "RESULT: PASS" in said and "power supply was lost" not in said, said
    assert "(1 late status packet); each then answered." in said, said


def test_statuses_later_than_the_retry_waits_are_said_as_a_slow_link_not_a_lost_cable(
    tmp_path: Path,
) -> None:
    """Late past the retry's wait too: the servo answered, so its cable and power are not
    in question (they had been named as lost); the slow link is."""
    cfg = _config(tmp_path, _late(12, 2.0))
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert "its status came on" in said and "but late (after the SDK's reply window)" in said
    assert "a slow USB-serial adapter" in said and "power supply was lost" not in said, said


def test_the_counts_said_are_plural_past_one() -> None:
    """The loaded-machine check's line had said "(109 late status packet)": each count now
    agrees with its number, whichever way the statuses were lost."""
    from rti_rig.drivers.dynamixel.bus import resends_said

    resent = ["id 1 read Present Position: late status packet" for _ in range(109)]
    resent += ["id 2 ping: no status packet"] * 2 + ["id 1 ping: damaged status packet"] * 3
    said = resends_said(resent)
    assert said == (
        "The arm's servos were asked again 114 times after a status packet was lost, late or "
        "damaged (109 late status packets, 2 lost status packets, 3 damaged status packets); "
        "each then answered."
    ), said
