"""`rti-rig check` on an arm stopped (Ctrl-C, SIGTERM) after "Checking …" was printed but
before the arm's connect: the rig was still being built (the emulator, the camera), and no
byte had gone to the servos.

The check had said "Check stopped (Ctrl-C): check the rig's lights." - a dome's sentence,
nothing of the arm, as if a lamp might be lit or the arm moving. It now says what it
established: nothing was sent to the arm. The stop is a real signal raised as the camera is
built (no race)."""

from __future__ import annotations

import signal
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
@pytest.mark.parametrize(
    ("sig", "code", "name"), [(signal.SIGINT, 130, "Ctrl-C"), (signal.SIGTERM, 143, "SIGTERM")]
)
def test_a_check_stopped_before_the_arm_connects_says_nothing_was_sent_to_it(
    monkeypatch: pytest.MonkeyPatch, sig: signal.Signals, code: int, name: str
) -> None:
    import rti_rig.app.compose as compose

    emulators: list[Any] = []
    real_keep, real_camera = compose._keep_powered_state, compose._simulated_camera

    def keep(loaded: Any, emulator: Any) -> Any:
        emulators.append(emulator)
        return real_keep(loaded, emulator)

    def camera(*args: Any, **kwargs: Any) -> Any:
        signal.raise_signal(sig)  # the stop, as the rig is built
        return real_camera(*args, **kwargs)

    monkeypatch.setattr(compose, "_keep_powered_state", keep)
    monkeypatch.setattr(compose, "_simulated_camera", camera)
    cfg: Path = CONFIGS / "simulated_arm.toml"
    r = CliRunner(env={"COLUMNS": "400"}).invoke(app, ["check", str(cfg)])
    text = said(r)
    assert r.exit_code == code, text
    assert "Traceback" not in text
    assert f"Check stopped ({name}): nothing was sent to the arm" in text, text
    assert "check the rig's lights" not in text, text
    (emulator,) = emulators
    assert emulator.instructions_received == 0  # the truth of "nothing was sent"
