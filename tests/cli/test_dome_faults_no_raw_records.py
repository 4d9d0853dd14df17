"""A dome's faults met during a run are said as the product speaks, never as raw log records.

Before, each resend after a lost, late or garbled reply was a WARNING record ("dome on
/tmp/…/tty-nab-rti-v1 (emulated nab-rti-v1): light LED 1 at level 1 failed (timeout, attempt
1): no reply within 3.01 s (lost or late)"), which the command line (configuring no logging)
printed raw on stderr in the middle of the progress bar; metering's connect had no listener,
so a port lost while metering was reopened with nothing said; and a port lost during the
teardown's all-off was said as "the session goes on once it is back" of a session that had
ended.
"""

from __future__ import annotations

import json
import logging
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.slow,  # real firmware timing over a pty, reply timeouts of 3 s
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
]

#: What the raw records had said (the policy's own words for a resend and a reopening).
RAW = ("failed (timeout, attempt", "failed (garbled, attempt", "failed (disconnected", "WARNING:")

#: A reply lost (a resend after the reply timeout) and one garbled, on the Nab sketch's
#: second and third lights (commands 6 and 9 over its pty).
RESENT_FAULTS = (
    '[[emulator.faults]]\nat_command = 6\nkind = "drop_reply"\n'
    '[[emulator.faults]]\nat_command = 9\nkind = "garble_reply"'
)


def _config(tmp_path: Path, faults: str) -> Path:
    cfg = tmp_path / "rig.toml"
    cfg.write_text((CONFIGS / "emulated_nab_rti_v1.toml").read_text() + f"\n{faults}\n")
    return cfg


def _run(
    tmp_path: Path, faults: str, caplog: pytest.LogCaptureFixture, *extra: str
) -> tuple[object, str, Path]:
    out = tmp_path / "S"
    argv = ["run", str(_config(tmp_path, faults)), "--lights", "6", "--out", str(out)]
    with caplog.at_level(logging.DEBUG):
        r = CliRunner().invoke(app, [*argv, "--no-verdict", *extra], terminal_width=400)
    # no rti-rig record at warning level, the level the command line would print raw
    loud = [x.getMessage() for x in caplog.records if x.levelno >= logging.WARNING]
    assert not [m for m in loud if "dome" in m], loud
    return r, " ".join(r.output.split()), out


def test_resends_that_went_through_are_counted_once_at_the_end_and_kept(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    r, said, out = _run(tmp_path, RESENT_FAULTS, caplog)
    assert r.exit_code == 0, said  # type: ignore[attr-defined]
    for raw in RAW:
        assert raw not in said, (raw, said)
    line = (
        "The dome's commands were resent 2 times after a fault (1 timeout, 1 garbled); "
        "each resent command then went through."
    )
    assert said.count(line) == 1, said
    assert "6 image(s) in the session" in said, said
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert runner["dome_resent"] == [
        "light LED 1 at level 1: timeout",
        "light LED 2 at level 1: garbled",
    ]


def test_a_run_without_faults_says_no_resends(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    r, said, out = _run(tmp_path, "", caplog)
    assert r.exit_code == 0, said  # type: ignore[attr-defined]
    assert "resent" not in said, said
    assert "dome_resent" not in json.loads((out / "manifest.json").read_text())["runner"]


def test_a_port_lost_during_the_teardown_all_off_is_said_as_being_for_it(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    # command 16 is the teardown's all-off after the sixth light (4 + 2 per light, then off)
    r, said, out = _run(
        tmp_path, '[[emulator.faults]]\nat_command = 16\nkind = "disconnect"', caplog
    )
    assert r.exit_code == 0, said  # type: ignore[attr-defined]
    lost = (
        "The dome dropped off the USB bus during 'all off': reopening its port (up to 4 "
        "attempts over 7.5 s); the closing all-off is sent again once it is back."
    )
    assert said.count(lost) == 1, said
    assert "goes on once it is back" not in said, said
    assert said.index("The dome is back") > said.index(lost), said
    assert "All-off sent and acknowledged by the dome: lights are off." in said, said
    for raw in RAW:
        assert raw not in said, (raw, said)
    [kept] = json.loads((out / "manifest.json").read_text())["runner"]["dome_reconnections"]
    assert kept["during"] == "all off" and kept["outcome"] == "reconnected"


def test_a_port_lost_while_metering_is_said_as_a_run_says_it(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    fault = '[[emulator.faults]]\nat_command = 3\nkind = "disconnect"'
    r, said, out = _run(tmp_path, fault, caplog, "--auto-exposure")
    assert r.exit_code == 0, said  # type: ignore[attr-defined]
    lost = "The dome dropped off the USB bus during 'light LED 10 at level 1': reopening its port"
    assert said.count(lost) == 1, said
    back = said.index("The dome is back: its port reopened and it answered, after ")
    assert said.index(lost) < back < said.index("Exposure fixed at"), said
    for raw in RAW:
        assert raw not in said, (raw, said)
    [kept] = json.loads((out / "manifest.json").read_text())["runner"]["dome_reconnections"]
    assert kept["during"] == "light LED 10 at level 1" and kept["outcome"] == "reconnected"


def test_the_console_entry_prints_no_raw_record_on_stderr(tmp_path: Path) -> None:
    # through `python -m rti_rig`, as a user's terminal gets it (Python's last-resort handler
    # prints any warning record no handler takes)
    out = tmp_path / "S"
    argv = ["run", str(_config(tmp_path, RESENT_FAULTS)), "--lights", "6", "--out", str(out)]
    env = {**os.environ, "COLUMNS": "400"}
    done = subprocess.run(
        [sys.executable, "-m", "rti_rig", *argv, "--no-verdict"],
        capture_output=True,
        text=True,
        timeout=600,
        env=env,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    for raw in (*RAW, "rti_rig.dome", "tty-nab-rti-v1 (emulated nab-rti-v1):"):
        assert raw not in done.stderr, (raw, done.stderr)
    assert "resent 2 times after a fault" in " ".join(done.stderr.split()), done.stderr
