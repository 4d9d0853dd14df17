"""A dome-fired camera whose files arrive late: the LED goes off after the exposure, not after
the file (through the CLI, a real firmware emulated on a pty, a tethering folder).

The shipped folder-watch config waits up to ``timeout_s`` = 15 s for a file while its dome
allows an LED ``max_on_s`` = 8 s. The LED had stayed lit until the file was in hand and
decoded, so a RAW that took 9 s over Wi-Fi ran into the thermal guard: the session stopped and
the good shot was lost, after the object had been lit nine times longer than the image needed.
"""

from __future__ import annotations

import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp
from rti_rig.drivers.cameras.dng_writer import linear_to_mosaic, write_dng
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

MAX_ON_S = 3.0
#: the tethering program saves each shot this long after the camera was fired: longer than
#: the LED may stay on, as a RAW over Wi-Fi can take
FILE_DELAY_S = 4.5


def _config(tmp_path: Path, port: str, tether: Path) -> Path:
    """The shipped nab-rti-v1 config as a real dome's: its port, the thermal limit above, a
    camera fired by the dome's shutter line whose files come into ``tether``."""
    text = (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
    text = text[: text.index("[scene]")]
    text = text.replace('backend = "emulated"', 'backend = "hardware"')
    text = text.replace('port = "emulated"', f'port = "{port}"')
    text = text.replace(
        "[dome.serial.protocol]",
        f"[dome.serial.thermal]\nmax_on_s = {MAX_ON_S}\n\n[dome.serial.protocol]",
    )
    text = text.replace(
        "exposure_s = 0.05\n",
        'exposure_s = 0.05\n\n[camera.device]\nkind = "folder_watch"\n'
        f'folder = "{tether}"\ntrigger = "dome_shutter"\ntimeout_s = 10.0\n',
        1,
    )
    cfg = tmp_path / "dome.toml"
    cfg.write_text(text)
    return cfg


class Tether(threading.Thread):
    """The camera and its tethering program: each shutter pulse the board saw becomes a DNG in
    the folder ``FILE_DELAY_S`` later (on the board's clock)."""

    def __init__(self, board, folder: Path) -> None:  # type: ignore[no-untyped-def]
        super().__init__(daemon=True)
        self.board, self.folder = board, folder
        self.stop = threading.Event()
        self.saved_at: list[float] = []

    def run(self) -> None:
        done = 0
        mosaic = linear_to_mosaic(np.full((48, 48), 0.3), "RGGB", 256, 4095)
        while not self.stop.is_set():
            pulses = [t for t, what in list(self.board.events) if what == "shutter"]
            if len(pulses) > done and self.board.clock.now() >= pulses[done] + FILE_DELAY_S:
                done += 1
                write_dng(
                    self.folder / f"IMG_{done:04d}.DNG",
                    mosaic,
                    black_level=256,
                    white_level=4095,
                    exposure_s=0.05,
                    iso=100,
                )
                self.saved_at.append(self.board.clock.now())
            self.stop.wait(0.02)


def _on_periods(timeline: list[tuple[float, frozenset[int]]]) -> list[tuple[float, float]]:
    """(on, off) times of every period with an LED lit, from the board's record."""
    periods, since = [], None
    for t, lit in timeline:
        if lit and since is None:
            since = t
        elif not lit and since is not None:
            periods.append((since, t))
            since = None
    return periods


@pytest.mark.slow  # three files each 4.5 s late, in real time
def test_a_late_file_does_not_keep_the_led_on_past_its_thermal_limit(tmp_path: Path) -> None:
    tether = tmp_path / "tether"
    tether.mkdir()
    out = tmp_path / "s"
    board = board_for("nab-rti-v1")
    camera = Tether(board, tether)
    camera.start()
    try:
        with serve_on_pty(board, "nab-rti-v1") as link:
            cfg = _config(tmp_path, link.port, tether)
            args = ["run", str(cfg), "--out", str(out), "--lights", "3", "--no-verdict"]
            r = CliRunner().invoke(app, args, terminal_width=300)
    finally:
        camera.stop.set()
        camera.join(5.0)
    assert r.exit_code == 0, r.output
    assert len(read_lp(out / "lights.lp")) == 3
    assert len(camera.saved_at) == 3
    # the boot lights every LED (the sketch's setup()); the session's own lights come after
    lit = [p for p in _on_periods(board.timeline) if p[0] > board.events[0][0]]
    session = lit[-3:]
    assert all(off - on < MAX_ON_S for on, off in session), session
    # each LED was off before its file was saved: the wait happened in the dark
    assert all(off < saved for (_, off), saved in zip(session, camera.saved_at, strict=True))
