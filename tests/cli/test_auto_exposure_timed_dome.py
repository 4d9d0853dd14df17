"""`rti-rig run --auto-exposure` on the shipped emulated RTIPy dome meters under lit LEDs only.

RTIPy lights an LED for 2 s and switches it off by itself. A test shot takes settle + exposure +
readout + transfer, about 1.1 s on this config, so a series of shots under one lighting
outlasted the window: its third shot was dark (mean 4 counts against 2571 lit), metering read
it as "nothing bright" and chose the longest exposure the window allows (0.95 s where 0.00136 s
keeps the brightest image within the limit), and the off after the series was refused ("LED 7
went dark by itself 3.42 s before the capture ended"): the run failed before its first image.
Each test shot now has a window of its own. The emulator's record is the truth: the LED lit at
every shot, metering's and the session's alike.
"""

from __future__ import annotations

import json
import re
import sys
import time
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

import rti_rig.app.compose as compose
from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.slow,  # in real time, as the real dome: about 3 s per test shot and per image
    pytest.mark.pty,
    pytest.mark.e2e,
]
runner = CliRunner()


class Spy:
    """Every shot the CLI's rigs take: its exposure and the LEDs the emulated board had lit as
    it began; and the boards, to read what they have lit after the run."""

    def __init__(self) -> None:
        self.shots: list[tuple[float, frozenset[int]]] = []
        self.boards: list = []  # type: ignore[type-arg]

    def dark_at_last(self, timeout_s: float = 5.0) -> bool:
        """Every board dark, once its last window has ended by itself (2 s; bounded)."""
        end = time.monotonic() + timeout_s
        while any(board.lit for board in self.boards):
            if time.monotonic() > end:
                return False
            time.sleep(0.01)
        return bool(self.boards)


@pytest.fixture
def spy(monkeypatch: pytest.MonkeyPatch) -> Spy:
    seen = Spy()
    real_build = compose.build_rig

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real_build(*args, **kwargs)
        board, real_capture = rig.emulator, rig.camera.capture

        def capture(exposure_s: float):  # type: ignore[no-untyped-def]
            seen.shots.append((exposure_s, board.lit))
            return real_capture(exposure_s)

        rig.camera.capture = capture
        seen.boards.append(board)
        return rig

    monkeypatch.setattr(compose, "build_rig", build)
    return seen


def test_metering_on_the_timed_rtipy_dome_shoots_each_test_shot_under_a_lit_led(
    tmp_path: Path, spy: Spy
) -> None:
    out = tmp_path / "s"
    args = ["run", str(CONFIGS / "emulated_rtipy.toml"), "--auto-exposure", "--lights", "3"]
    r = runner.invoke(app, [*args, "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    said = " ".join(r.output.split())
    m = json.loads((out / "manifest.json").read_text(encoding="utf-8"))
    chosen = m["schedule"]["provenance"]["exposure"]
    n, shots = chosen["metering_shots"], spy.shots
    # every shot, metering's and the session's, began under one lit LED
    assert len(shots) == n + 3, shots
    assert all(len(lit) == 1 for _, lit in shots), shots
    assert [t for t, _ in shots[:n]] == [
        t for ts in chosen["test_exposures_by_light_s"] for t in ts
    ]
    # so no dark shot chose the exposure: well below the longest the window allows (0.95 s, which
    # a dark shot had chosen; the matte tablet meters at about 0.08 s), and the images at it keep
    # within the rule
    assert chosen["shot_per_lighting"] is True
    assert chosen["exposure_s"] < chosen["rule"]["max_exposure_s"] / 4
    limit = chosen["rule"]["max_saturated_fraction"]
    assert [s["saturated_fraction"] <= limit for s in m["steps"]] == [True] * 3
    assert "each test shot is taken under a window of its own" in said
    # what the run took includes the metering (about 3 s a shot here), said with its shot count
    line = re.search(r"Session time on the real rig: ([0-9.]+) s including (\d+) metering", said)
    assert line is not None, said
    assert int(line.group(2)) == n
    total = m["timing"]["rig_time_s"] + chosen["rig_time_s"]
    assert float(line.group(1)) == pytest.approx(total, abs=0.05)
    # the lights: never said to be off (this firmware has no all-off), and dark at the end
    assert "lights are off" not in said and "went dark by itself" not in said
    assert spy.dark_at_last()
