"""What a device must tell the user as it happens is said in the product's words, never as a raw
log record on stderr.

Before, the command line (which configures no logging) printed an arm's and a dome's warning
and error records raw through Python's last-resort handler, in the middle of the progress bar:
the arm's "not at the park pose, so torque stays on" of ``release_on_close``, its search for
the servos at the other baud rates, a second failure while closing it after a first ("teardown
step failed", or "stop after timeout failed"), and a dome's "error while closing the port".
Each is now one line naming the device, with what to do, through the device's ``listen``
(said by ``run`` and ``check``), or with no listener a warning record that the command line
says as a note (``records_as_notes``): never lost, never raw.
"""

from __future__ import annotations

import logging
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO, inprocess_arm_config, said, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.shell_words import shell_word

#: What the raw records had said, in any of their forms.
RAW = (
    "WARNING:",
    "ERROR:",
    "not at the park pose, so torque stays on",
    "teardown step failed",
    "stop after timeout failed",
    "error while closing the port",
    "looking for them at the other",
    "held despite a hardware alert",
)

RELEASED_UNPARKED = (
    'torque_policy = "release_on_close"',
    "park_after_session = false",
)


def torque_line(cfg: Path) -> str:
    """The line said of the torque kept on, whose check names ``cfg``, ready to paste (a bare
    'rti-rig check' had been said, refused when pasted for its missing config)."""
    return (
        "arm: torque stays on: the arm is not at its park pose, and torque_policy = "
        '"release_on_close" releases it only there, where it cannot drop onto the object. Park '
        f"it with rti-rig check {shell_word(cfg)} --park-only before switching off the "
        "servos' power."
    )


def _release_unparked(tmp_path: Path) -> Path:
    """The emulated arm (in-process servos) releasing its torque at the close, not parked."""
    cfg = inprocess_arm_config(tmp_path)
    text = cfg.read_text()
    assert 'torque_policy = "hold"' in text and "\n[arm]\n" in text
    text = text.replace('torque_policy = "hold"', RELEASED_UNPARKED[0])
    text = text.replace("\n[arm]\n", f"\n[arm]\n{RELEASED_UNPARKED[1]}\n", 1)
    cfg.write_text(text)
    return cfg


def _loud(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [
        r.getMessage()
        for r in caplog.records
        if r.levelno >= logging.WARNING and r.name.startswith("rti_rig")
    ]


def test_run_says_the_torque_kept_on_once_in_words(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    out = tmp_path / "S"
    cfg = _release_unparked(tmp_path)
    argv = ["run", str(cfg), "--lights", "2", "--out", str(out)]
    with caplog.at_level(logging.DEBUG):
        r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    text = said(r)
    assert r.exit_code == 0, text
    assert text.count(torque_line(cfg)) == 1, text
    assert not _loud(caplog), _loud(caplog)  # said through the run, not as a record
    for raw in RAW:
        assert raw not in text, (raw, text)


def test_the_installed_command_says_it_on_stderr_with_no_raw_record(tmp_path: Path) -> None:
    """Through ``python -m rti_rig`` (the console entry, logging as a user's shell has it):
    stderr holds the product's lines and nothing in a log record's form."""
    out = tmp_path / "S"
    cfg = _release_unparked(tmp_path)
    proc = subprocess.run(
        [sys.executable, "-m", "rti_rig", "run", str(cfg), "--lights", "2", "--out", str(out)],
        env={**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "400"},
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
    )
    both = " ".join((proc.stdout + proc.stderr).split())
    assert proc.returncode == 0, both
    assert both.count(torque_line(cfg)) == 1, both
    for raw in RAW:
        assert raw not in proc.stderr, (raw, proc.stderr)


def test_check_says_the_torque_kept_on(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """``check`` parks the arm unless park_after_session is off: then its close keeps the
    torque on, and says so once."""
    with caplog.at_level(logging.DEBUG):
        cfg = _release_unparked(tmp_path)
        r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    text = said(r)
    assert text.count(torque_line(cfg)) == 1, text
    assert not _loud(caplog), _loud(caplog)
    for raw in RAW:
        assert raw not in text, (raw, text)


@pytest.mark.pty
def test_check_says_the_search_at_other_baud_rates_before_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """Servos set to 1 Mbps, a config at 57600 (a user's bus, served by the emulator's tool on
    a pty): the up-to-10-s search is said before it, once, then the error names the rate."""
    import dynamixel_sdk

    from rti_rig.core.clock import SystemClock
    from rti_rig.simulator.dynamixel_emulator import arm_settings_of, served_arm

    settings, where = arm_settings_of(None)
    with served_arm(settings, SystemClock(), 1_000_000) as (server, _):
        port = server.device_path
        monkeypatch.setattr(dynamixel_sdk, "PortHandler", lambda _path: server.port_handler())
        text = Path(where).read_text()
        text = text.replace('backend = "emulated"', 'backend = "hardware"')
        text = text.replace('transport = "pty"', "")
        text = re.sub(r'port = "emulated".*', f'port = "{port}"', text)
        (tmp_path / "tether").mkdir()
        text += f'\n[camera.device]\nkind = "folder_watch"\nfolder = "{tmp_path / "tether"}"\n'
        cfg = tmp_path / "arm.toml"
        cfg.write_text(text)
        with caplog.at_level(logging.DEBUG):
            r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    text = said(r)
    line = (
        f"arm on {port}: no servo answers at 57600 baud (the [arm.dynamixel] baudrate); looking "
        "for the servos at the other X-series rates, a read-only broadcast ping each (up to "
        "about 10 s)."
    )
    assert text.count(line) == 1, text
    assert "1000000" in text.split(line, 1)[1], text  # the error after it names the rate
    assert not _loud(caplog), _loud(caplog)
    for raw in RAW:
        assert raw not in text, (raw, text)


def test_a_shipped_config_has_what_these_tests_edit() -> None:
    text = (CONFIGS / "simulated_arm.toml").read_text()
    assert 'torque_policy = "hold"' in text and 'name = "arm"' in text


def test_a_servo_alert_s_run_says_its_fault_with_no_record_beside_it(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """The elevation servo reports an input-voltage fault mid-run, one it does not shut down
    for: its error (torque still on) and the teardown are said in words; that the stop then
    held the alerted servo is a detail the log keeps below warning level (it had been a raw
    "arm: servo 2 held despite a hardware alert: …" record on stderr)."""
    cfg = inprocess_arm_config(tmp_path, servo_fault(80, 2, "input_voltage"))
    out = tmp_path / "S"
    with caplog.at_level(logging.DEBUG):
        r = CliRunner().invoke(
            app, ["run", str(cfg), "--lights", "6", "--out", str(out)], terminal_width=400
        )
    text = said(r)
    assert r.exit_code == 2, text
    assert "servo 2: hardware fault input voltage" in text, text
    assert "its torque is still ON" in text, text
    assert not _loud(caplog), _loud(caplog)
    for raw in RAW:
        assert raw not in text, (raw, text)
