"""``rti-rig probe`` stops listening once an answer names a firmware, and says what it tries.

Every listen had run its whole window (2.6 s after each opening) even after a whole banner or
reply: the Nab sketch's banner, over about 2 s after the port opens, was listened to 0.6 s
more, and a nichlock board at 9600 waited out its window. Listening on where an answer is not
yet complete (a banner cut short, silence) still runs the whole window. The probe also said
nothing for the 25 s that a silent port takes: each probe is now announced on stderr.

Through the command line on a port whose time is virtual (a read that finds nothing advances
it by its timeout; the probe's own clock is the same): the time a listen took is read from
that clock, never from the wall.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest
from typer.testing import CliRunner

import rti_rig.app.usecases.probe as probe_usecase
from rti_rig.cli import app
from rti_rig.core.clock import VirtualClock

#: nichlock's boot at the rate its EEPROM holds: its banner 1 s after the opening (the
#: bootloader), the rest after ``beginDisplay``'s 0.45 s; ``cut`` ends it before its prompt.
NICHLOCK_BOOT = [
    (1.0, b"Serial initialized from EEPROM\r\n"),
    (1.01, b"Reflectance Transformation Imager Serial Interface v1.0\nDISABLE LINE ENDINGS\r\n"),
    (1.46, b"Initialized Display.\r\n1\r\nSetting channel color names:\r\n"),
    (1.47, b"UV      \r\nWhite   \r\nIR      \r\n\nFor help, press 'h'\n>"),
]


NICHLOCK_BANNER = "Reflectance Transformation Imager Serial Interface v1.0\n"


class _ScriptedPort:
    """A serial port (pyserial's side) whose board says ``boot`` (seconds after the opening,
    bytes) when opened at ``rate``; at any other rate, or after it, nothing. A read that finds
    nothing due waits its timeout (at least 1 ms) on ``clock``, or until the next bytes."""

    def __init__(self, clock: VirtualClock, boot: list[tuple[float, bytes]], **kwargs: Any):
        self._clock = clock
        self.timeout = kwargs.get("timeout")
        start = clock.now()
        self._due = [(start + at, data) for at, data in boot]

    @property
    def in_waiting(self) -> int:
        return sum(len(data) for at, data in self._due if at <= self._clock.now())

    def read(self, n: int) -> bytes:
        if not self._due:
            self._clock.sleep(max(self.timeout or 0.0, 0.001))
            return b""
        wait = self._due[0][0] - self._clock.now()
        if wait > 0:
            self._clock.sleep(min(wait, max(self.timeout or 0.0, 0.001)))
        out = bytearray()
        while self._due and self._due[0][0] <= self._clock.now() and len(out) < n:
            out += self._due.pop(0)[1]
        return bytes(out)

    def write(self, data: bytes) -> int:
        return len(data)

    def flush(self) -> None:
        pass

    def close(self) -> None:
        pass


def _probe(
    monkeypatch: pytest.MonkeyPatch, rate: int, boot: list[tuple[float, bytes]]
) -> tuple[Any, list[tuple[str, float]]]:
    """Probe a port whose board says ``boot`` at ``rate``: the command's result, and each
    opening's (rate, virtual seconds since the first)."""
    import serial

    clock = VirtualClock()
    openings: list[tuple[str, float]] = []

    def open_port(url: str, *args: Any, baudrate: int, **kwargs: Any) -> _ScriptedPort:
        openings.append((f"{baudrate}", clock.now()))
        return _ScriptedPort(clock, boot if baudrate == rate else [], **kwargs)

    monkeypatch.setattr(serial, "serial_for_url", open_port)
    monkeypatch.setattr(probe_usecase, "time", SimpleNamespace(monotonic=clock.now))
    r = CliRunner().invoke(app, ["probe", "/dev/ttyUSB0"], terminal_width=400)
    openings.append(("end", clock.now()))
    return r, openings


def test_a_whole_nichlock_banner_ends_the_listen_at_its_prompt(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    r, openings = _probe(monkeypatch, 9600, NICHLOCK_BOOT)
    assert r.exit_code == 0, r.output
    assert 'profile = "nichlock"' in r.output and "baudrate = 9600" in r.output, r.output
    (_, opened), (end, ended) = openings
    assert end == "end" and ended - opened == pytest.approx(1.47, abs=0.11), openings


def test_a_banner_cut_before_its_prompt_is_listened_to_for_the_whole_window(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    r, openings = _probe(monkeypatch, 9600, NICHLOCK_BOOT[:2])
    assert r.exit_code == 0, r.output
    assert 'profile = "nichlock"' in r.output and "baudrate = 9600" in r.output, r.output
    (_, opened), (_, ended) = openings
    assert ended - opened >= 2.6, openings  # the prompt, or a calibration, may still come


def test_an_answer_at_another_rate_ends_that_listen_only(monkeypatch: pytest.MonkeyPatch) -> None:
    """At 19200 (nichlock's menu): the listens at 9600 and 115200 heard nothing and ran their
    whole windows; the one at 19200 ended at the prompt."""
    r, openings = _probe(monkeypatch, 19200, NICHLOCK_BOOT)
    assert r.exit_code == 0, r.output
    assert "baudrate = 19200" in r.output, r.output
    rates = [rate for rate, _ in openings]
    assert rates == ["9600", "115200", "19200", "end"], openings
    times = [at for _, at in openings]
    assert times[1] - times[0] >= 2.6 and times[2] - times[1] >= 2.6, openings
    assert times[3] - times[2] == pytest.approx(1.47, abs=0.11), openings


def test_each_probe_is_announced_with_the_firmwares_it_is_for(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A silent port: nine probes, each said on stderr as it begins (the command had been
    silent for their 25 s), stdout's lines unchanged."""
    r, openings = _probe(monkeypatch, 9600, [])
    assert r.exit_code == 1, r.output
    trying = [line for line in r.stderr.splitlines() if line.startswith("Trying ")]
    assert trying == [
        "Trying the Nab sketch (RTI v1.0), nichlock, rti-rig's own protocols (listen at 9600 "
        "baud)…",
        "Trying nichlock, rti-rig's own protocols (listen at 115200 baud)…",
        "Trying nichlock (listen at 19200 baud)…",
        "Trying nichlock (listen at 2400 baud)…",
        "Trying Elexol 24R1 ('?' at 38400 baud)…",
        "Trying nichlock ('m' (free RAM) at 115200 baud)…",
        "Trying minirti (0x42 + empty mask at 9600 baud)…",
        "Trying the Nab sketch (RTI v1.0) ('<9>' (an unknown code) at 9600 baud)…",
        "Trying RTIPy ('T,0,0,0' at 9600 baud)…",
    ], r.stderr
    # one opening each, the last three on one (each opening resets an Arduino), then the end
    assert len(openings) == 8, openings
    assert "Trying" not in r.stdout and "No known dome firmware answered" in r.stdout


def test_mask_unknown_code_and_t000_share_one_opening(monkeypatch: pytest.MonkeyPatch) -> None:
    """minirti's mask (1.6 s after the opening, as its host waits 1.5 s), the Nab sketch's
    ``<9>`` (once a probe's 2.6 s for a bootloader and banner are over) and RTIPy's
    ``T,0,0,0`` are sent on one opening at 9600, where each had its own (a reset, its boot
    waited out, each time). ``T,0,0,0`` waits for 1.5 s of the probe's silence, past the 1 s
    that ends a command on RTIPy's sketch (sooner, it was part of the ``<9>``'s command). On a
    silent port: the mask's two listens of 0.5 s, ``<9>``'s two of 0.6 s from 2.6 s, the
    silence, then T's two listens of 1.8 s (virtual time)."""
    r, openings = _probe(monkeypatch, 9600, [])
    assert r.exit_code == 1, r.output
    (rate, opened), (end, ended) = openings[-2:]
    assert (rate, end) == ("9600", "end"), openings
    second_nine = 2.6 + 0.6
    assert ended - opened == pytest.approx(second_nine + 1.5 + 1.8 + 1.8, abs=0.11), openings


@pytest.mark.parametrize(
    ("text", "reply", "answered"),
    [
        ("RTI-Dome intialized\r\n<6> Single photo\r\n=====\r\n", None, True),
        ("RTI-Dome intialized\r\n<6> Single photo\r\n==", None, False),  # the banner goes on
        ("<INCORRECT FUNCTION CALL: 9>", "<INCORRECT FUNCTION CALL: 9>", True),
        (NICHLOCK_BANNER, None, False),
        (
            f"{NICHLOCK_BANNER}1\r\nTouch screen was not calibrated. Starting Calibration..",
            None,
            True,
        ),
        (f"{NICHLOCK_BANNER}1\r\nSetting channel color names:\r\n", None, False),
        (f"{NICHLOCK_BANNER}\nFor help, press 'h'\n>", None, True),
        ("Did nothing; that key is not assigned to a command.\r\n", "", True),
        ("Did nothing; that key is not assig", "", False),
        ("USB I/O 24R1", "USB I/O 24R1", True),
        ("\x01", None, False),  # before anything was sent: no acknowledgement
        ("\x01", "\x01", True),
        ("\x01\x01", "\x01\x01", True),  # a late acknowledgement read with the next one
        ("\x01\x01\x01", "\x01\x01\x01", True),
        ("\x01\x00", "\x01\x00", False),
        ("\x00\x01", "\x00\x01", False),
        ("I received: T,0,0,0 the instructionByte was: ", "", False),
        ("I received: T,0,0,0 the instructionByte was: T", "", True),
        ("READY RTIDOME-EMU 1.0.0 48*6A", None, False),  # its line not over
        ("READY RTIDOME-EMU 1.0.0 48*6A\r\n", None, True),
        ("\xfe\x8a\x1c garbage at another rate", None, False),
        ("", None, False),
    ],
)
def test_what_counts_as_an_answer_that_names_a_firmware(
    text: str, reply: str | None, answered: bool
) -> None:
    assert probe_usecase._answered(text, reply) is answered
