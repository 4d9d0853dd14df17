"""The "RTI v1.0" sketch's emulator (``simulator/domes/nab_rti_v1.py``) against the sketch's source.

The source is Sjors H. Nab's "RTI v1.0" Arduino sketch (2024): ``callFunction`` runs
``uvPhoto`` for code 4 and ``rti`` for code 5, and ``parseData`` splits the frame with
``strtok``. The board runs in-process on a virtual clock, so its own waits cost no real time.
"""

from __future__ import annotations

from rti_rig.core.clock import VirtualClock
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.domes.board import Board

ALL = frozenset(range(64))


def booted() -> tuple[Board, VirtualClock]:
    clock = VirtualClock()
    board = board_for("nab-rti-v1", clock=clock)
    board.on_port_opened()
    clock.sleep(3.0)  # bootloader, then setup(): every LED on, the banner
    assert board.lit == ALL
    return board, clock


def send(board: Board, clock: VirtualClock, data: bytes, seconds: float) -> str:
    """What the sketch prints within ``seconds`` of receiving ``data``."""
    out = board.receive(data)
    clock.sleep(seconds)
    out += board.tick()
    return b"".join(o.data for o in out).decode("latin-1")


def test_code_5_runs_the_sketchs_own_capture_and_ends_fully_lit() -> None:
    """``<5,ms>`` lights LED 0 to 63 in turn, one shutter each, then ``lightsOn()``.

    The emulator had answered ``<not emulated>`` and changed nothing, where the sketch blocks
    for minutes and leaves every LED lit."""
    board, clock = booted()
    start = clock.now()
    said = send(board, clock, b"<5,100>", 64 * (0.55 + 0.1) + 1.0)
    singles = [lit for t, lit in board.timeline if t >= start and len(lit) == 1]
    assert singles == [frozenset({i}) for i in range(64)]
    assert board.lit == ALL
    assert sum(1 for t, what in board.events if t >= start and what == "shutter") == 64
    assert "<Time to completion: 0 minutes and 31 seconds>" in said  # the sketch's int maths
    assert "<Completion: 84%>" in said and said.count("<Shutter triggered.>") == 64
    assert said.rstrip().endswith("<RTI Capture Completed>\r\n===================")


def test_code_4_shoots_under_uv_and_ends_fully_lit() -> None:
    board, clock = booted()
    send(board, clock, b"<0>", 0.5)
    assert board.lit == frozenset()
    start = clock.now()
    said = send(board, clock, b"<4,200>", 2.0)
    assert "<UV Turned on.>" in said and "<UVF Photograph taken>" in said
    assert sum(1 for t, what in board.events if t >= start and what == "shutter") == 1
    assert board.lit == ALL and not board.uv  # type: ignore[attr-defined]


def test_empty_fields_are_skipped_as_strtok_does() -> None:
    """``strtok`` skips empty fields, so ``<3,,7>`` lights LED 7 (the emulator had lit LED 0)."""
    board, clock = booted()
    said = send(board, clock, b"<3,,7>", 0.5)
    assert board.lit == frozenset({7})
    assert "<Single LED turned on, number: 7, row: 0, column: 7>" in said
