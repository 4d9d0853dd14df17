"""A busy DSLR on a timed firmware (RTIPy): its LED goes dark by itself after ``light_on_s``.

The rig is the shipped emulated RTIPy config made a hardware one (``backend = "hardware"``, a
gphoto2 camera), run through ``rti-rig run``: the RTIPy board's emulator is served on a pty and
the config's port redirected there (everything above ``serial.serial_for_url`` is the real
stack), and python-gphoto2 is the fake module, whose body writes to a slow card (busy, no
picture, for a time after each shot). Each picture is rendered from what the board really has
lit when the body takes it, so a picture taken in the dark shows it.

The board runs in real time, as the real one does (its LED goes dark 2 s after it lit), so
these tests take seconds; nothing here asserts on how long anything took.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import CONFIGS, write_config
from dng_spec_writer import dng, mosaic_from_rgb
from fake_gphoto2 import Body, make_module
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.clock import SystemClock
from rti_rig.core.image_files import read_linear_tiff

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.slow,  # in real time, as the real dome: its LED window is 2 s
    pytest.mark.pty,
    pytest.mark.e2e,
]

PORT = "/dev/ttyRTIPY-test"
H = W = 48
BLACK, WHITE = (512, 512, 512, 512), 16383


def level(lit: frozenset[int]) -> float:
    """How bright the picture is under what the board has lit (dark: 0)."""
    return 0.0 if len(lit) != 1 else 0.4 + 0.01 * next(iter(lit))


def rtipy_dslr_config(tmp_path: Path) -> Path:
    """emulated_rtipy.toml on the real dome (its port) with a gphoto2 DSLR at 1/8 s."""
    text = (CONFIGS / "emulated_rtipy.toml").read_text()
    for old, new in (
        ('backend = "emulated"', 'backend = "hardware"'),
        ('port = "emulated"', f'port = "{PORT}"'),
        ("exposure_s = 0.05\n", "exposure_s = 0.125\n"),
    ):
        assert old in text
        text = text.replace(old, new, 1)
    text = text.split("[scene]")[0]  # a hardware rig has no simulated scene
    text += '\n[camera.device]\nkind = "gphoto2"\nimage_format = "RAW"\nbusy_retries = 6\n'
    return write_config(tmp_path, text, "rtipy_dslr.toml")


@pytest.fixture
def rig_parts(monkeypatch: pytest.MonkeyPatch) -> Iterator[tuple[Any, Body, list]]:
    """(the RTIPy board on a pty, the camera body, what the board had lit at each shot)."""
    import serial

    from rti_rig.simulator.domes import board_for
    from rti_rig.simulator.pty_link import serve_on_pty

    board = board_for("rtipy", clock=SystemClock())
    lit_at_shots: list[frozenset[int]] = []
    with serve_on_pty(board, "rtipy") as link:

        def render(body: Body) -> bytes:
            link.wait_delivered()  # what the UART has delivered by now, whatever the load
            lit = frozenset(board.lit)
            lit_at_shots.append(lit)
            rgb = np.full((H, W, 3), level(lit))
            return dng(mosaic_from_rgb(rgb, "RGGB", BLACK, WHITE), "RGGB", BLACK, WHITE)

        body = Body(render=render, clock=SystemClock(), busy_clock=SystemClock())
        monkeypatch.setitem(sys.modules, "gphoto2", make_module(body))
        real = serial.serial_for_url

        def redirect(url, *args, **kwargs):  # type: ignore[no-untyped-def]
            return real(link.port if url == PORT else url, *args, **kwargs)

        monkeypatch.setattr(serial, "serial_for_url", redirect)
        yield board, body, lit_at_shots


def journal(out: Path) -> list[dict]:
    return [json.loads(x) for x in (out / "journal.jsonl").read_text().splitlines() if x]


def test_a_busy_camera_on_rtipy_is_awaited_in_the_dark_and_shot_under_a_new_window(
    tmp_path: Path, rig_parts: tuple[Any, Body, list]
) -> None:
    """A body busy 7 s after each shot: its tries come after 0.5, 1, 2… s, and RTIPy keeps the
    LED lit 2 s. The busy wait had counted max_on_s (10 s by default) as the LED's time: the
    body fired with the LED dark by itself, and the all-off refused the image late ("LED 1
    went dark by itself 5.73 s before the capture ended … raise light_on_s"). The LED is now
    left to go dark once the camera's next try would come after its window, the camera awaited
    in the dark, and the LED lit again by a new ``T,x,y,2`` for the shot."""
    board, body, lit_at_shots = rig_parts
    body.busy_for_s = 7.0
    out = tmp_path / "s"
    args = [str(rtipy_dslr_config(tmp_path)), "--out", str(out), "--lights", "2"]
    result = CliRunner().invoke(app, ["run", *args, "--no-verdict"])
    said = " ".join(result.output.split())
    assert result.exit_code == 0, result.output
    entries = journal(out)
    leds = [e["led"] for e in entries]
    # every picture the body took, it took under the step's own LED: none in the dark
    assert lit_at_shots == [frozenset({led}) for led in leds] and body.shots == 2
    assert entries[0].get("relit", []) == []
    relit = entries[1]["relit"]
    assert relit and all(r["off"] == "self-timed" for r in relit)
    for e in entries:
        tif = read_linear_tiff(out / e["linear_image"]) / 65535
        assert tif.mean() == pytest.approx(level(frozenset({e["led"]})), rel=1e-3)
    assert (
        f"would keep LED {leds[1]} (lit" in said
        and "past the 2 s the rtipy firmware keeps it lit before switching it off by itself "
        "(light_on_s): gone dark by itself at the end of its window"
        in said
    ), said
    # the board's own record: the second LED lit again (a new timed command) for each relight,
    # one LED at a time, each gone dark by itself before the next lit
    lightings = [lit for _, lit in board.timeline if lit]
    assert lightings == [frozenset({leds[0]})] + [frozenset({leds[1]})] * (1 + len(relit))
