"""A hang-up (SIGHUP: the terminal or ssh connection closing) during ``preview`` stops it as
SIGTERM does: the lit LED switched off, the stop named SIGHUP, exit 129 (``calibrate-lights``'
case is in test_calibrate_sigterm.py, beside its SIGTERM case, sharing its card session).

Before, only ``run``, ``check`` and ``probe`` answered a hang-up: ``preview`` (which lights the
dome) ended at once with its LED lit and no all-off, ``calibrate-lights``, ``fit`` and ``plan``
mid-write. The SIGHUP is raised in the command's own process at the point under test (no
timing); a handler set by the test beforehand turns an unhandled SIGHUP into a failure rather
than the end of pytest.
"""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, SighupUnhandled, manifest, said, sighup_at_lit_led
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.deferred_signals import signal_handlers

pytestmark = pytest.mark.skipif(
    sys.platform != "linux" or not hasattr(signal, "SIGHUP"), reason="signals tested on Linux"
)


def test_a_hangup_during_preview_switches_the_lit_led_off_and_exits_129(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, hangup_guarded: None
) -> None:
    out = tmp_path / "p"
    with monkeypatch.context() as patched:
        firmwares = sighup_at_lit_led(patched, 1)
        r = CliRunner().invoke(
            app, ["preview", str(CONFIGS / "emulated_dome.toml"), "--out", str(out)]
        )
    text = said(r)
    assert not isinstance(r.exception, SighupUnhandled), text
    assert r.exit_code == 129, text  # 128 + SIGHUP, as the shell reports a hang-up
    assert "Traceback" not in text and "SIGTERM" not in text, text
    assert "SIGHUP" in text, text
    # the emulator's truth: the LED lit when the hang-up came was switched off after it
    (firmware,) = firmwares
    assert firmware.lit is None
    events = [e.what for e in firmware.history]
    assert "lit" in events and events[-1] == "off", events
    assert "SIGHUP" in str(manifest(out)["runner"]["error"])


def test_a_preview_started_with_the_hangup_ignored_goes_on_to_its_image(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``nohup rti-rig preview …``: SIGHUP ignored as the command begins stays ignored."""
    out = tmp_path / "p"
    with monkeypatch.context() as patched, signal_handlers({signal.SIGHUP: signal.SIG_IGN}):
        sighup_at_lit_led(patched, 1)
        r = CliRunner().invoke(
            app, ["preview", str(CONFIGS / "emulated_dome.toml"), "--out", str(out)]
        )
        assert signal.getsignal(signal.SIGHUP) == signal.SIG_IGN
    assert r.exit_code == 0, said(r)
    assert manifest(out)["runner"]["finish_reason"] == "completed"
