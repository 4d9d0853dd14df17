"""``rti-rig probe`` switches a Nab dome off while nobody reads its stderr.

Each probe is told on stderr as it begins ("Trying …"), and a probe is told while a board may
be lit (the Nab sketch boots with every LED on at each opening). The telling was a print in
the probe's own thread: with stderr a full pipe nobody reads (a parent that stopped reading;
the CLI waits on a full non-blocking pipe rather than drop words), the probe waited in the
print, the dome lit, for as long as the reader did. Now the lines are said from a thread of
their own, and the probe, its all-off included, never waits on them.

Through the front door: ``python -m rti_rig probe`` on the sketch's emulator served on a pty,
its stderr a pipe filled to the brim and never read.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ended_on_exit, eventually

from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

pytestmark = [pytest.mark.pty, pytest.mark.e2e]


def _full_pipe() -> tuple[int, int]:
    """A pipe (read end, write end) whose buffer is full: a write to it waits for a reader.
    Its write end is non-blocking, as a parent (node's child_process, some CI runners) sets."""
    r, w = os.pipe()
    os.set_blocking(w, False)
    while True:
        try:
            os.write(w, b"x" * 4096)
        except BlockingIOError:
            break
    while True:  # the last page's room too
        try:
            os.write(w, b"x")
        except BlockingIOError:
            return r, w


def test_a_nab_dome_is_switched_off_while_stderr_is_never_read() -> None:
    board = board_for("nab-rti-v1")
    r, w = _full_pipe()
    try:
        with serve_on_pty(board, "nab-rti-v1") as link:
            proc = subprocess.Popen(
                [sys.executable, "-m", "rti_rig", "probe", link.port],
                stdout=subprocess.DEVNULL,
                stderr=w,
                cwd=Path(__file__).resolve().parents[2],
            )
            with ended_on_exit(proc):  # killed by its own handle and reaped, however it ends
                # lit at its boot (every LED), then dark: the all-off, acknowledged, went
                # through with the probe's first "Trying" line still waiting for room
                lit_then_dark = eventually(
                    lambda: (
                        any(len(lit) == board.led_count for _, lit in board.timeline)
                        and board.lit_once_booted() == frozenset()
                    ),
                    timeout_s=120,
                )
                assert lit_then_dark, (board.timeline, board.events)
                assert proc.poll() is None  # its words still wait for a reader: none lost
    finally:
        os.close(r)
        os.close(w)
    assert board.lit_once_booted() == frozenset()
