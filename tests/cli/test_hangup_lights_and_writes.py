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
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, manifest, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.deferred_signals import signal_handlers

pytestmark = pytest.mark.skipif(
    sys.platform != "linux" or not hasattr(signal, "SIGHUP"), reason="signals tested on Linux"
)


class Unhandled(Exception):
    """Raised by the test's own SIGHUP handler: the command installed none."""


@pytest.fixture
def hangup_guarded() -> Iterator[None]:
    """A SIGHUP nothing in rti-rig answers fails the test (its default would end pytest)."""

    def unhandled(signum: int, frame: Any) -> None:
        raise Unhandled("SIGHUP was not handled by rti-rig (the default ends the process)")

    with signal_handlers({signal.SIGHUP: unhandled}):
        yield


def _hangup_once_lit(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """SIGHUP raised in the command's process once its first LED is lit (the emulated
    firmware has acknowledged it); the firmwares built from here on, to read their truth."""
    import rti_rig.simulator.dome_firmware as dome_firmware
    from rti_rig.runtime.dome_policy import DomePolicy

    firmwares: list[Any] = []
    real_firmware_for = dome_firmware.firmware_for

    def firmware_for(*args: Any, **kwargs: Any) -> Any:
        firmware = real_firmware_for(*args, **kwargs)
        firmwares.append(firmware)
        return firmware

    real_light = DomePolicy.light
    raised: list[int] = []

    def light(self: Any, index: int, intensity: float = 1.0) -> None:
        real_light(self, index, intensity)
        if len(firmwares) == 1 and not raised and firmwares[0].lit is not None:
            raised.append(index)
            signal.raise_signal(signal.SIGHUP)

    monkeypatch.setattr(dome_firmware, "firmware_for", firmware_for)
    monkeypatch.setattr(DomePolicy, "light", light)
    return firmwares


def test_a_hangup_during_preview_switches_the_lit_led_off_and_exits_129(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, hangup_guarded: None
) -> None:
    out = tmp_path / "p"
    with monkeypatch.context() as patched:
        firmwares = _hangup_once_lit(patched)
        r = CliRunner().invoke(
            app, ["preview", str(CONFIGS / "emulated_dome.toml"), "--out", str(out)]
        )
    text = said(r)
    assert not isinstance(r.exception, Unhandled), text
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
        _hangup_once_lit(patched)
        r = CliRunner().invoke(
            app, ["preview", str(CONFIGS / "emulated_dome.toml"), "--out", str(out)]
        )
        assert signal.getsignal(signal.SIGHUP) == signal.SIG_IGN
    assert r.exit_code == 0, said(r)
    assert manifest(out)["runner"]["finish_reason"] == "completed"
