"""An rti-rig log record at warning level that no listener took is said as a note on stderr,
once, in its own words; records below warning level stay off the terminal.

Before, the command line configured no logging, so such a record reached Python's last-resort
handler and was printed raw in the middle of the progress bar (and a record below warning level
never, which is right for the drivers' diagnostics).
"""

from __future__ import annotations

import logging
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import REPO, inprocess_arm_config

from rti_rig.cli.app import PRODUCT_LOGGER, records_as_notes


@pytest.fixture
def notes_installed() -> Iterator[None]:
    logger = logging.getLogger(PRODUCT_LOGGER)
    before = list(logger.handlers)
    records_as_notes()
    records_as_notes()  # twice, as two commands in one process would: one handler
    try:
        yield
    finally:
        logger.propagate = True
        for handler in logger.handlers[:]:
            if handler not in before:
                logger.removeHandler(handler)


def test_a_warning_record_is_a_note_once_and_an_info_record_is_not_said(
    notes_installed: None, capsys: pytest.CaptureFixture[str]
) -> None:
    log = logging.getLogger("rti_rig.dome")
    log.warning("%s: its port did not close cleanly", "dome on COM3")
    log.warning("%s: its port did not close cleanly", "dome on COM3")
    log.info("dome on COM3: reconnection 1 failed: gone")  # a diagnostic
    logging.getLogger("rti_rig.dynamixel.arm").error("arm: the stop failed too")
    err = " ".join(capsys.readouterr().err.split())
    assert (
        err == "note: dome on COM3: its port did not close cleanly note: arm: the stop failed too"
    )


def test_a_root_handler_someone_configured_does_not_print_it_raw_again(
    notes_installed: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """pyserial's ``socket://…?logging=debug`` port URL calls ``logging.basicConfig()``: the
    record had then been printed a second time, as ``WARNING:rti_rig.dome:…``."""
    root = logging.getLogger()
    raw = logging.StreamHandler(sys.stderr)
    raw.setFormatter(logging.Formatter(logging.BASIC_FORMAT))
    root.addHandler(raw)
    try:
        logging.getLogger("rti_rig.dome").warning("dome on COM3: its port did not close cleanly")
    finally:
        root.removeHandler(raw)
    err = capsys.readouterr().err
    assert "WARNING:" not in err, err
    assert " ".join(err.split()) == "note: dome on COM3: its port did not close cleanly", err


#: The run of the console entry (``rti_rig.cli.main``, which installs the note handler) with
#: the arm's listener never set: its line then goes out as a warning record.
HOOK = """
import sys
from rti_rig.runtime.lighting import ArmLighting
ArmLighting.listen = lambda self, say: None
from rti_rig.cli import main
sys.argv = ["rti-rig", *sys.argv[1:]]
main()
"""


def test_the_console_entry_says_a_record_no_listener_took_as_a_note(tmp_path: Path) -> None:
    cfg = inprocess_arm_config(tmp_path)
    text = cfg.read_text().replace('torque_policy = "hold"', 'torque_policy = "release_on_close"')
    cfg.write_text(text.replace("\n[arm]\n", "\n[arm]\npark_after_session = false\n", 1))
    hook = tmp_path / "hook.py"
    hook.write_text(HOOK)
    out = tmp_path / "S"
    proc = subprocess.run(
        [
            sys.executable,
            str(hook),
            "run",
            str(cfg),
            "--lights",
            "3",
            "--out",
            str(out),
            "--no-verdict",
        ],
        env={**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "400"},
        capture_output=True,
        text=True,
        timeout=600,
    )
    err = " ".join(proc.stderr.split())
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert err.count("note: arm: torque stays on: the arm is not at its park pose") == 1, err
    for raw in ("WARNING:", "\narm: torque stays on"):
        assert raw not in proc.stderr, proc.stderr
