"""A SIGTERM during `rti-rig calibrate-lights` stops it as Ctrl-C does: no hidden temporary file
left in the card session, what was written said, exit 143, and the session calibrates again.

Why: calibrate-lights had no SIGTERM handler (run and fit have theirs): a SIGTERM (``timeout``,
a scheduler) while the calibration was written ended the process at once, leaving a hidden
``.light_calibration.toml.tmp`` in the card session, and said nothing. The signal is sent to
this process from inside the command, at the point under test (no sleeps).
"""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from card_support import card_rig, shoot
from conftest import said
from sigterm_support import Unhandled, sigterm_fails_the_test, terminated
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.cli import calibrate as calibrate_cli
from rti_rig.core.deferred_signals import signal_handlers

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")

runner = CliRunner()


@pytest.fixture(autouse=True)
def _sigterm_fails_the_test_not_the_run() -> Iterator[None]:
    with sigterm_fails_the_test("calibrate-lights"):
        yield


@pytest.fixture(scope="module")
def card(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A card rig and a card session shot on it (shared: each test calibrates it anew)."""
    where = tmp_path_factory.mktemp("card")
    rig = card_rig(where)
    session = where / "card é"
    shoot(rig, session)
    return rig, session


def test_a_sigterm_mid_write_leaves_no_temporary_file_and_calibrates_again(
    card: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    rig, session = card
    before = sorted(p.name for p in session.iterdir())
    real = Path.write_text
    cut: list[Path] = []

    def write_text(self: Path, data: str, *args: Any, **kwargs: Any) -> int:
        if self.name == ".light_calibration.toml.tmp":
            real(self, data[: len(data) // 2], *args, **kwargs)  # as far as it got
            cut.append(self)
            terminated()
        return real(self, data, *args, **kwargs)

    argv = ["calibrate-lights", str(session), "--rig", str(rig)]
    with monkeypatch.context() as m:
        m.setattr(Path, "write_text", write_text)
        r = runner.invoke(app, argv)

    text = said(r)
    assert len(cut) == 1, text
    assert r.exit_code == 143, text
    assert not isinstance(r.exception, Unhandled), text
    assert "Traceback" not in text, text
    assert (
        f"Stopped (SIGTERM) before the calibration was written: nothing was written to "
        f"{session / 'light_calibration.toml'}"
    ) in text, text
    assert sorted(p.name for p in session.iterdir()) == before  # no .light_calibration.toml.tmp
    assert signal.getsignal(signal.SIGTERM).__name__ == "unhandled"  # the command's only
    again = runner.invoke(app, argv)
    assert again.exit_code == 0, again.output
    assert "calibrated already" not in said(again)
    (session / "light_calibration.toml").unlink()  # the session as the next test finds it


def test_a_sigterm_once_written_says_the_calibration_and_its_line(
    card: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    rig, session = card
    target = tmp_path / "cal é.toml"
    printed = calibrate_cli.out.print

    def interrupted(*args: Any, **kwargs: Any) -> None:
        if args and str(args[0]).startswith("Calibration →"):
            terminated()  # as the file's line is printed
        printed(*args, **kwargs)

    monkeypatch.setattr(calibrate_cli.out, "print", interrupted)

    r = runner.invoke(
        app, ["calibrate-lights", str(session), "--rig", str(rig), "--out", str(target)]
    )

    text = said(r)
    assert r.exit_code == 143, text
    assert not isinstance(r.exception, Unhandled), text
    rel = os.path.relpath(target.resolve(), rig.resolve().parent)
    assert (
        f"Stopped (SIGTERM): the calibration {target} is written; to use it, set "
        f'intensity_correction_file = "{rel}" under [dome.serial] in {rig}'
    ) in text, text
    assert 'format = "rti-rig-light-calibration/1"' in target.read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == [target.name]


@pytest.mark.skipif(not hasattr(signal, "SIGHUP"), reason="no SIGHUP on this platform")
def test_a_hangup_mid_write_leaves_no_temporary_file_and_exits_129(
    card: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A hang-up (SIGHUP: the terminal or ssh connection closing) is answered as SIGTERM is,
    and named as itself: it had no handler, and ended the command at once mid-write."""
    rig, session = card
    before = sorted(p.name for p in session.iterdir())
    real = Path.write_text
    cut: list[Path] = []

    def write_text(self: Path, data: str, *args: Any, **kwargs: Any) -> int:
        if self.name == ".light_calibration.toml.tmp":
            real(self, data[: len(data) // 2], *args, **kwargs)  # as far as it got
            cut.append(self)
            os.kill(os.getpid(), signal.SIGHUP)  # handled at the next bytecode
        return real(self, data, *args, **kwargs)

    def unhandled(signum: int, frame: Any) -> None:
        raise Unhandled("SIGHUP reached the test's handler: calibrate-lights installed none")

    argv = ["calibrate-lights", str(session), "--rig", str(rig)]
    with monkeypatch.context() as m, signal_handlers({signal.SIGHUP: unhandled}):
        m.setattr(Path, "write_text", write_text)
        r = runner.invoke(app, argv)

    text = said(r)
    assert len(cut) == 1, text
    assert not isinstance(r.exception, Unhandled), text
    assert r.exit_code == 129, text  # 128 + SIGHUP, as the shell reports a hang-up
    assert "Traceback" not in text and "SIGTERM" not in text, text
    assert (
        f"Stopped (SIGHUP) before the calibration was written: nothing was written to "
        f"{session / 'light_calibration.toml'}"
    ) in text, text
    assert sorted(p.name for p in session.iterdir()) == before  # no .light_calibration.toml.tmp
