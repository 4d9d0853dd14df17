"""``rti-rig probe`` keeps what it heard when a stop lands, and switches a lit Nab board off.

A Nab board resets at every opening of its port and boots with every LED lit. What a probe had
heard was kept only once a listen returned, so a stop inside a listen (or in the closing after
it) lost a banner already received: the dome was left lit under "stopped before a firmware
answered". A board booting in 3.3 to 4 s (its profile allows 4 s) was sent its all-off while
still in its bootloader. Each test runs the command against the firmware's emulator on a
pseudo-terminal; a stop is raised where a signal lands (a read, a closing, the gap between two
ports), which no timing could aim a real signal at.
"""

from __future__ import annotations

import signal
import time
from types import SimpleNamespace
from typing import Any

import pytest
from typer.testing import CliRunner

from rti_rig.app.usecases import probe as probe_usecase
from rti_rig.cli import app
from rti_rig.drivers.led_dome.transport import SerialTransport
from rti_rig.runtime.controller import EmergencyStop
from rti_rig.simulator.dome_firmware import Fault, FaultKind, FaultPlan
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

pytestmark = [pytest.mark.pty, pytest.mark.e2e]

#: The words the stop says of a Nab board switched off.
SWITCHED_OFF = "the sketch boots with every LED on; all-off sent and acknowledged"

#: A Nab board slow to boot: later than the probe's 2.6 s listen and its two all-offs sent
#: 0.6 s apart, within the 4 s its profile allows (``boot_wait_s``).
SLOW_BOOT_S = 3.5


def _boots(board: Any) -> int:
    return sum(what == "boot" for _, what in board.events)


def _probe(board: Any, name: str) -> tuple[int, str]:
    """``rti-rig probe`` on ``board`` served on a pty: its exit code and output, unwrapped."""
    with serve_on_pty(board, name) as link:
        r = CliRunner().invoke(app, ["probe", link.port], terminal_width=400)
    return r.exit_code, " ".join(r.output.split())


def _stopped_in_a_read_once_heard(
    monkeypatch: pytest.MonkeyPatch, baud: int, words: str, why: signal.Signals = signal.SIGTERM
) -> list[str]:
    """Raise the stop from the read that follows the one completing ``words`` on a port open at
    ``baud``: the signal landing in a listen that has already heard them."""
    real_read = SerialTransport.read
    heard = bytearray()
    stops: list[str] = []

    def read_then_stopped(self: SerialTransport, timeout_s: float) -> bytes:
        if self.baudrate == baud and not stops and words in heard.decode("latin-1"):
            stops.append(words)
            raise EmergencyStop(why)
        data = real_read(self, timeout_s)
        if self.baudrate == baud and not stops:
            heard.extend(data)
        return data

    monkeypatch.setattr(SerialTransport, "read", read_then_stopped)
    return stops


def test_a_stop_in_the_listen_after_the_nab_banner_switches_the_dome_off(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """SIGTERM in the first listen, after the board booted lit and its whole banner was read:
    the banner was lost with the stop, the teardown listened for a boot already over, and the
    dome was left lit (exit 143, "stopped before a firmware answered")."""
    stops = _stopped_in_a_read_once_heard(monkeypatch, 9600, "<6> Single photo")
    board = board_for("nab-rti-v1")
    code, said = _probe(board, "nab-rti-v1")
    assert stops, "the listen never heard the banner"
    assert code == 143, said
    assert "before a firmware answered" not in said, said
    assert f"Probe stopped (SIGTERM): {SWITCHED_OFF}" in said, said
    assert 'profile = "nab-rti-v1"' in said and "Traceback" not in said, said
    assert _boots(board) == 1, board.events  # switched off on the port it had open
    assert board.lit_once_booted() == frozenset()


def test_a_stop_as_the_first_port_closes_keeps_the_nab_banner_it_heard(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A Ctrl-C in the closing of the first port, whose listen heard the Nab banner: the text
    was dropped, so the lines heard and the teardown knew nothing of the sketch."""
    real_close = SerialTransport.close
    stops: list[str] = []

    def close_then_stopped(self: SerialTransport) -> None:
        real_close(self)
        if not stops:
            stops.append(self.port)
            raise EmergencyStop(signal.SIGINT)

    monkeypatch.setattr(SerialTransport, "close", close_then_stopped)
    board = board_for("nab-rti-v1")
    code, said = _probe(board, "nab-rti-v1")
    assert code == 130 and stops, said
    assert "listen at 9600 baud: '" in said and "Single photo" in said, said
    assert f"Probe stopped (Ctrl-C): {SWITCHED_OFF}" in said, said
    assert board.lit_once_booted() == frozenset()


def test_a_nab_board_slow_to_boot_is_switched_off_once_its_banner_is_over() -> None:
    """A board that boots in 3.5 s: its all-off went after a fixed 2.6 s and again 0.6 s later,
    both into its bootloader; the dome was left lit, and the probe exited 0."""
    board = board_for("nab-rti-v1")
    board.boot_s = SLOW_BOOT_S
    code, said = _probe(board, "nab-rti-v1")
    assert code == 0, said
    assert f"Lights: {SWITCHED_OFF}" in said, said
    assert board.lit_once_booted() == frozenset()


def test_a_slow_nab_board_stopped_before_it_is_named_is_switched_off(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The same slow board, the stop landing as the probe begins to switch it off on the port
    its banner (begun) was heard on: the teardown's all-off, on that same port (the board not
    reset again), waits for the rest of its banner too."""
    stops: list[tuple[str | None, int]] = []

    def stopped(result: probe_usecase.ProbeResult, *args: Any) -> None:
        stops.append((result.profile, _boots(board)))
        raise EmergencyStop(signal.SIGINT)

    monkeypatch.setattr(probe_usecase, "_nab_off_on_open_port", stopped)
    board = board_for("nab-rti-v1")
    board.boot_s = SLOW_BOOT_S
    code, said = _probe(board, "nab-rti-v1")
    assert code == 130 and len(stops) == 1 and stops[0][0] is None, (stops, said)
    assert f"Probe stopped (Ctrl-C): {SWITCHED_OFF}" in said, said
    assert _boots(board) == stops[0][1], board.events  # no opening after the stop
    assert board.lit_once_booted() == frozenset()


def test_an_all_off_not_acknowledged_is_not_a_success() -> None:
    """Both of the all-off's replies lost: the lights are not confirmed off, and the probe had
    exited 0 as one that succeeded."""
    board = board_for(
        "nab-rti-v1",
        faults=FaultPlan((Fault(1, FaultKind.DROP_REPLY), Fault(2, FaultKind.DROP_REPLY))),
    )
    code, said = _probe(board, "nab-rti-v1")
    assert code == 1, said
    assert "error: the Nab sketch did not acknowledge its all-off <0>" in said, said
    assert "NOT acknowledged: check the dome" in said and "Traceback" not in said, said


def test_a_stop_between_two_ports_reopens_at_9600_and_switches_the_nab_off(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A Ctrl-C after the first port closed (its listen over before the slow board booted),
    before the next opened: the opening had reset the board, which boots lit; the probe said
    "look at the dome" and left it so."""
    real_exchange = probe_usecase._exchange
    stops: list[str] = []

    def then_stopped(result: probe_usecase.ProbeResult, what: str, *args: Any) -> str:
        text = real_exchange(result, what, *args)
        if not stops:
            stops.append(what)
            raise EmergencyStop(signal.SIGINT)
        return text

    monkeypatch.setattr(probe_usecase, "_exchange", then_stopped)
    board = board_for("nab-rti-v1")
    board.boot_s = SLOW_BOOT_S
    code, said = _probe(board, "nab-rti-v1")
    assert code == 130 and stops, said
    assert f"Probe stopped (Ctrl-C): {SWITCHED_OFF}" in said, said
    assert 'profile = "nab-rti-v1"' in said and "Traceback" not in said, said
    assert _boots(board) == 2, board.events
    assert board.lit_once_booted() == frozenset()


def test_a_stop_after_nichlocks_banner_at_115200_names_it_and_does_not_reset_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A Ctrl-C in the listen at 115200 after nichlock's board printed its banner: the port was
    opened a third time at 9600 (a reset) to look for a Nab board, and the stop said "stopped
    before a firmware answered"."""
    stops = _stopped_in_a_read_once_heard(
        monkeypatch, 115200, "Reflectance Transformation Imager Serial Interface", signal.SIGINT
    )
    board = board_for("nichlock")
    code, said = _probe(board, "nichlock")
    assert stops, "the listen at 115200 never heard the banner"
    assert code == 130, said
    assert "before a firmware answered" not in said, said
    assert "Probe stopped (Ctrl-C): the firmware boots with every LED off" in said, said
    assert 'profile = "nichlock"' in said and "baudrate = 115200" in said, said
    assert _boots(board) == 2, board.events  # 9600, then 115200: not reset a third time


def test_a_nab_board_first_heard_by_the_last_probe_is_switched_off() -> None:
    """A board that boots in 3.9 s is heard by none of the probes before RTIPy's ``T,0,0,0``,
    whose longer listen hears its banner: the probe said "No known dome firmware answered",
    exit 1, the banner among the lines heard and the dome lit."""
    board = board_for("nab-rti-v1")
    board.boot_s = 3.9
    code, said = _probe(board, "nab-rti-v1")
    assert code == 0, said
    assert "Found: nab-rti-v1" in said and f"Lights: {SWITCHED_OFF}" in said, said
    assert board.lit_once_booted() == frozenset()


def test_a_stop_between_two_ports_after_nichlocks_banner_names_it_and_does_not_reset_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A Ctrl-C as the listen at 115200 returns with nichlock's banner, before the probe
    looked at it: the board answered, so the teardown names it rather than open the port
    again at 9600 (a reset) to look for a Nab board."""
    real_exchange = probe_usecase._exchange
    stops: list[str] = []

    def then_stopped(result: probe_usecase.ProbeResult, what: str, *args: Any) -> str:
        text = real_exchange(result, what, *args)
        if not stops and what == "listen at 115200 baud":
            stops.append(what)
            raise EmergencyStop(signal.SIGINT)
        return text

    monkeypatch.setattr(probe_usecase, "_exchange", then_stopped)
    board = board_for("nichlock")
    code, said = _probe(board, "nichlock")
    assert code == 130 and stops, said
    assert "before a firmware answered" not in said, said
    assert "Probe stopped (Ctrl-C): the firmware boots with every LED off" in said, said
    assert 'profile = "nichlock"' in said and "baudrate = 115200" in said, said
    assert _boots(board) == 2, board.events  # 9600, then 115200: not reset a third time


# The teardown decides on typed data (each listen's rate in ``Heard.baud``, the lights in
# ``ProbeResult.lights_state``), not on the words it prints: it had read the rate back out of
# a listen's label ("at N baud") and cleared an error by how its words began.


def test_a_listen_label_without_its_rate_still_names_nichlock_at_its_rate(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The stop between two ports after nichlock's banner at 115200, its listens labelled with
    no "at N baud" in the words: the firmware is named at the rate its port was open at, and
    the port is not opened again at 9600 (a reset)."""
    monkeypatch.setattr(probe_usecase, "_LISTEN_SAID", "listening ({baud} bd)")
    real_exchange = probe_usecase._exchange
    stops: list[str] = []

    def then_stopped(result: probe_usecase.ProbeResult, what: str, baud: int, *args: Any) -> str:
        text = real_exchange(result, what, baud, *args)
        if not stops and baud == 115200:
            stops.append(what)
            raise EmergencyStop(signal.SIGINT)
        return text

    monkeypatch.setattr(probe_usecase, "_exchange", then_stopped)
    board = board_for("nichlock")
    code, said = _probe(board, "nichlock")
    assert code == 130 and stops == ["listening (115200 bd)"], (stops, said)
    assert "listening (115200 bd):" in said, said  # the reworded label is what is printed
    assert "Probe stopped (Ctrl-C): the firmware boots with every LED off" in said, said
    assert 'profile = "nichlock"' in said and "baudrate = 115200" in said, said
    assert _boots(board) == 2, board.events  # 9600, then 115200: not reset a third time


class _NabLine:
    """A stand-in for the Nab board's open port: each write of the all-off is answered with
    ``replies``' next (empty: the reply lost)."""

    baudrate = 9600

    def __init__(self, *replies: bytes) -> None:
        self.replies = list(replies)
        self.pending = b""

    def write(self, data: bytes) -> None:
        self.pending += self.replies.pop(0) if self.replies else b""

    def read(self, timeout: float) -> bytes:
        out, self.pending = self.pending, b""
        return out


#: The Nab sketch's answer to its all-off, as its emulator prints it.
_OFF_REPLY = b"<UV Turned off.>\n<All lights turned off.>\n"


def test_an_acknowledged_all_off_clears_the_unacknowledged_ones_error_whatever_its_words(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """An all-off sent twice unanswered, then (a stop's teardown) once more and acknowledged:
    its error is cleared however its words are put (they had to begin with the words of
    ``_NOT_ACKNOWLEDGED``); the labels of the all-offs reworded change only what is printed."""
    monkeypatch.setattr(probe_usecase, "_ALL_OFF_SAID", "switching off ({command})")
    monkeypatch.setattr(probe_usecase, "_ALL_OFF_AGAIN_SAID", "once more ({command})")
    result = probe_usecase.ProbeResult("/dev/ttyACM9")
    probe_usecase._nab_off(result, _NabLine())  # type: ignore[arg-type]
    assert result.lights_state is probe_usecase.LightsState.OFF_NOT_ACKNOWLEDGED
    assert result.error is not None
    monkeypatch.setattr(probe_usecase, "_NOT_ACKNOWLEDGED", "reworded")
    probe_usecase._nab_off(result, _NabLine(_OFF_REPLY))  # type: ignore[arg-type]
    assert result.lights_state is probe_usecase.LightsState.OFF_ACKNOWLEDGED
    assert result.error is None
    assert [h.label for h in result.heard] == [
        "switching off (<0>)",
        "once more (<0>)",
        "switching off (<0>)",
    ]
    assert all(h.baud == 9600 for h in result.heard)


def test_a_stop_after_an_acknowledged_all_off_does_not_reopen_whatever_was_printed(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A stop with no port open after the Nab board acknowledged its all-off: the port is not
    opened again (a reset, every LED lit once more) whatever the lines heard say, decided on
    the lights' state (it had searched the transcript for the reply's words)."""

    def reopened(result: probe_usecase.ProbeResult, wait: float) -> Any:
        raise AssertionError("the port was opened again after an acknowledged all-off")

    monkeypatch.setattr(probe_usecase, "_nab_found", reopened)
    result = probe_usecase.ProbeResult(
        "/dev/ttyACM9",
        profile="nab-rti-v1",
        baudrate=9600,
        heard=[probe_usecase.Heard("reworded", 9600, "")],
        openings=2,
    )
    probe_usecase._say_lights(result, probe_usecase.LightsState.OFF_ACKNOWLEDGED)
    probe_usecase._stopped_between_ports(result, 0.1)
    assert result.lights_state is probe_usecase.LightsState.OFF_ACKNOWLEDGED
    assert result.lights == "the sketch boots with every LED on; all-off sent and acknowledged"


def test_a_stop_as_the_port_has_just_opened_is_torn_down_on_that_port(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A Ctrl-C landing once the port had opened, as the probe read the opening's time (before
    the try whose handler tears a stop down on the open port): the stop escaped with the port
    still open and locked, the teardown opened it again ("another program holds it") and the
    Nab dome, reset by the opening, was left lit. Injected at that very point: the first read
    of the clock after an opening."""
    real_open = SerialTransport.open
    opened: list[str] = []
    stops: list[str] = []

    def open_then_flag(self: SerialTransport) -> None:
        real_open(self)
        opened.append(self.port)

    def monotonic() -> float:
        if opened and not stops:
            stops.append("stopped")
            raise EmergencyStop(signal.SIGINT)
        return time.monotonic()

    monkeypatch.setattr(SerialTransport, "open", open_then_flag)
    monkeypatch.setattr(probe_usecase, "time", SimpleNamespace(monotonic=monotonic))
    board = board_for("nab-rti-v1")
    code, said = _probe(board, "nab-rti-v1")
    assert code == 130 and stops, said
    assert f"Probe stopped (Ctrl-C): {SWITCHED_OFF}" in said, said
    assert "another program" not in said and "Traceback" not in said, said
    assert _boots(board) == 1, board.events  # torn down on the port it opened, not reopened
    assert board.lit_once_booted() == frozenset()


def test_a_stop_after_the_sketchs_answer_to_a_code_sends_its_all_off_without_waiting() -> None:
    """A stop's teardown on a port where the sketch has answered ``<9>`` (its banner over, or
    lost): the sketch is running, so its all-off goes at once. The teardown listened for the
    banner's last line only, and so waited out the rest of the 4 s its profile allows a boot,
    the dome lit, for a line that had come or never would. Counted in reads of the port
    before the all-off (none: nothing is waited for)."""

    class Line(_NabLine):
        reads_before_the_off = 0
        written = False

        def write(self, data: bytes) -> None:
            self.written = True
            super().write(data)

        def read(self, timeout: float) -> bytes:
            self.reads_before_the_off += not self.written
            return super().read(timeout)

    line = Line(_OFF_REPLY)
    result = probe_usecase.ProbeResult("/dev/ttyACM9")
    heard = "<INCORRECT FUNCTION CALL: 9>\r\n"
    probe_usecase._stopped_on_open_port(
        result,
        line,  # type: ignore[arg-type]
        9600,
        time.monotonic(),
        2.6,
        heard,
    )
    assert line.reads_before_the_off == 0
    assert result.profile == "nab-rti-v1"
    assert result.lights_state is probe_usecase.LightsState.OFF_ACKNOWLEDGED
