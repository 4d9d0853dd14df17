"""``rti-rig probe PORT``: which known dome firmware answers on a serial port.

Least intrusive first: listen to what the board prints when the port opens (the Nab sketch and
nichlock's firmware print banners), then ask questions that light nothing (the Elexol board's
``?``), then commands that switch everything off (minirti's all-zero mask), and last RTIPy's
``T,0,0,0`` (LED 0 for zero seconds). A firmware identified with its LEDs possibly on (the Nab
sketch boots fully lit) is sent its all-off before the probe returns: the Nab sketch on the
port it was heard on, still open (opening it again reset the board a second time, lit again,
its boot waited out twice). A dome that never answers
(hadrian2/RTI_Dome) cannot be identified; the result says so, with what was heard.

Ctrl-C or SIGTERM (raised as :class:`EmergencyStop` by the command's handler) stops the probe
through a teardown, as it stops a check: opening the port, at whatever rate, resets a Nab
board, which boots at 9600 with every LED on, so a stop on a port open at 9600 listens out the
board's boot on that same port (reopening would reset it again) and sends the sketch's all-off
if its banner comes; a stop on a port open at another rate, inside any opening, or between
two ports, opens the port again at 9600 and does the same, unless what was heard shows another
firmware (nichlock's banner), which is named instead; a Nab board identified is sent its
all-off once its banner is over. What a listen heard is kept as it comes, so a stop loses none
of it.
:class:`ProbeStopped` then says what is known of the lights (it had said only "stopped
(Ctrl-C)", a dome lit in full behind it).
"""

from __future__ import annotations

import errno
import os
import re
import stat
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum, auto

from rti_rig.core.shell_words import shell_word
from rti_rig.core.toml_strings import NotTomlText, toml_basic_string
from rti_rig.drivers.led_dome.codec_binary import BinaryCodec
from rti_rig.drivers.led_dome.codec_default import DefaultCodec
from rti_rig.drivers.led_dome.codec_framed import FramedCodec, FramedSpec
from rti_rig.drivers.led_dome.damaged_reply import one_byte_off
from rti_rig.drivers.led_dome.dome_profiles import nab_rti_v1 as nab
from rti_rig.drivers.led_dome.dome_profiles import rtipy
from rti_rig.drivers.led_dome.messages import Banner
from rti_rig.drivers.led_dome.transport import PortHeldError, SerialTransport, TransportError
from rti_rig.runtime.controller import EmergencyStop


@dataclass(frozen=True)
class ProbeRequest:
    port: str
    #: Seconds to listen after opening (covers an Arduino's bootloader and banner).
    listen_s: float = 2.6


@dataclass(frozen=True)
class Heard:
    """What one listen of the probe heard: ``label`` is only said (the line printed before the
    text); what the probe decides is taken from ``baud`` and ``text``. A stop's teardown had read
    the rate back out of the label ("at N baud"), so rewording a label changed which firmware
    it named and whether it reset the board once more."""

    #: What the listen was, as printed ("listen at 9600 baud", "all off <0>" …).
    label: str
    #: The rate the port was open at.
    baud: int
    #: All the port sent meanwhile.
    text: str


class LightsState(Enum):
    """What the probe established of the lights, as it decides on it; the words said
    (:attr:`ProbeResult.lights`) are built from it where it is set (:func:`_say_lights`). The
    teardown had decided by searching its own transcript and error text for the words of an
    acknowledgement: rewording a line changed what it did."""

    #: A firmware found whose probes light nothing (the Elexol board's ``?``); the default.
    NOTHING_LIT = auto()
    #: Stopped before the port was ever opened.
    NEVER_OPENED = auto()
    #: The port could not be opened: nothing was sent.
    PORT_UNUSABLE = auto()
    #: The port opened (a reset) and failed before any firmware answered.
    PORT_FAILED_UNANSWERED = auto()
    #: The port failed after some probes, none of which lights an LED.
    PORT_FAILED_AFTER_PROBES = auto()
    #: The port failed during a stop's teardown: the dome's state is not known.
    PORT_FAILED_IN_STOP = auto()
    #: Stopped after an opening (a reset) before any firmware answered.
    STOPPED_UNANSWERED = auto()
    #: No firmware answered; a board slow to boot may light after the probe.
    UNANSWERED = auto()
    #: nichlock's firmware: it boots with every LED off.
    BOOTS_DARK = auto()
    #: minirti: the all-off mask was sent and acknowledged.
    MASK_ACKNOWLEDGED = auto()
    #: RTIPy: LED 0 was asked for zero seconds.
    ZERO_SECONDS = auto()
    #: The Nab sketch, lit at boot: its all-off was acknowledged.
    OFF_ACKNOWLEDGED = auto()
    #: The Nab sketch, lit at boot: its all-off was sent twice, not acknowledged.
    OFF_NOT_ACKNOWLEDGED = auto()
    #: The Nab sketch, lit at boot: its all-off could not be sent (the port failed).
    OFF_NOT_SENT = auto()
    #: The Nab sketch, lit at boot: its all-off was written, then the port failed before an
    #: acknowledgement (said "could NOT be sent", of an all-off the board may have obeyed).
    OFF_SENT_PORT_FAILED = auto()


class ProbeFailure(Enum):
    """What went wrong with a probe, as a caller decides on it (:attr:`ProbeError.failure`):
    the conclusion said, and whether a later acknowledged all-off clears it. They had been
    decided on a free-form error string being set at all, so a port that opened and then
    failed before anything was heard was told "The port could not be opened"."""

    #: The probe's port could not be opened: nothing was sent on it.
    PORT_NOT_OPENED = auto()
    #: The port failed once open (a read, a write), or in a stop's teardown.
    PORT_FAILED = auto()
    #: The Nab sketch did not acknowledge its all-off, sent twice: the dome may be lit.
    OFF_NOT_ACKNOWLEDGED = auto()


@dataclass(frozen=True)
class ProbeError:
    """A probe's error: ``failure``, decided on, and ``said``, the words printed (``str()``
    gives them, as the free-form string it replaces did)."""

    failure: ProbeFailure
    said: str

    def __str__(self) -> str:
        return self.said


class _PortNotOpened(TransportError):
    """The opening of the probe's port failed (raised from :func:`_exchange`, the transport's
    own error carried: its words, ``errno`` and whether another program holds the port's
    lock), told from a port that failed once open."""

    def __init__(self, message: str, *, errno: int | None = None, held: bool = False) -> None:
        super().__init__(message, errno=errno)
        self.held = held


@dataclass
class ProbeResult:
    port: str
    #: The rig config the user will put the config lines in (``probe --rig``; None: not
    #: named): the check the notes advise names it, as shell words, so that it pastes.
    rig: str | None = None
    profile: str | None = None
    #: The baud rate the firmware answered at (with ``profile``).
    baudrate: int | None = None
    #: What each probe heard, in the order tried.
    heard: list[Heard] = field(default_factory=list)
    #: What is known of the lights, said (built from :attr:`lights_state`).
    lights: str = "nothing was lit by the probe"
    #: What is known of the lights, decided on.
    lights_state: LightsState = LightsState.NOTHING_LIT
    #: What went wrong, typed (None: nothing); printed as its words on stderr.
    error: ProbeError | None = None
    #: What else the firmware showed that the user must act on before a check (or None).
    note: str | None = None
    #: Why the firmware found cannot be used as it is (None: it can): a banner the profile's
    #: codec refuses. The probe then exits 1, as the check would fail: it had said "Found:
    #: default" and exited 0 for a board every check of which then failed on its banner.
    unusable: str | None = None
    #: How many times a port opening was attempted (each resets a board like an Arduino).
    openings: int = 0
    #: The opening (its number in :attr:`openings`) on which the Nab sketch's all-off was last
    #: written (0: never): a port failing after it says "sent, but not acknowledged" only while
    #: no opening since has reset the board, lit again.
    off_written_at_opening: int = 0
    #: What the port's path is when it is no serial port ("is a regular file" …; None: it
    #: may be one), said in place of advice to check the dome's cable and power.
    not_serial: str | None = None
    #: The port is there but this user may not open it (EACCES): its error says what to do,
    #: and advice to check the dome's cable and power is not given beside it.
    permission_denied: bool = False
    #: The port is there but another program holds its lock (another rti-rig's check or
    #: session on this dome): the advice is to wait for it or stop it, not to check the cable.
    port_held: bool = False
    #: Config lines the firmware's answer showed beyond ``[dome.serial]`` (a default-profile
    #: board without checksums).
    extra_lines: list[str] = field(default_factory=list)
    #: Told each probe as it begins: its label ("listen at 9600 baud" …) and the firmwares it
    #: is for ("the Nab sketch, nichlock, rti-rig's own"), so that a caller can say which is
    #: being tried: a port where nothing answers takes over 20 s, and the command had said
    #: nothing meanwhile. Not told of a stop's teardown's openings, nor of the Nab sketch's.
    on_try: Callable[[str, str], None] | None = field(default=None, repr=False, compare=False)

    def config_lines(self) -> list[str]:
        if self.profile is None:
            return []
        # the rate it answered at is said too: a config copied from the example (or the
        # guide) keeps its "baudrate = 115200", which overrides the profile's own rate, and
        # a 9600-baud firmware then failed its check with no word of the rate that works
        rate = [f"baudrate = {self.baudrate}"] if self.baudrate is not None else []
        lines = ["[dome.serial]", _port_line(self.port), f'profile = "{self.profile}"', *rate]
        return lines + self.extra_lines

    def check_command(self) -> str:
        """The check to run once the config lines are in place: with the rig config named
        (``--rig``) as shell words, a command that pastes; without, what to add to it.

        Why: the notes ended "then run rti-rig check", which pasted is refused for its
        missing rig config."""
        if self.rig:
            return f"rti-rig check {shell_word(self.rig)}"
        return (
            "rti-rig check with the rig config you put these lines in (probe --rig CONFIG "
            "names it here, as a command to paste)"
        )

    def heard_lines(self) -> list[str]:
        """What each probe heard, one line each (the end of a long text)."""
        out = []
        for heard in self.heard:
            shown = heard.text.strip().replace("\r", "")[-200:] or "(nothing)"
            out.append(f"{heard.label}: {shown!r}")
        return out

    def lines(self) -> list[str]:
        """What was heard, then :meth:`conclusion_lines` (for stdout; :attr:`error` is not
        among them: the command says it on stderr between the two, as every other command says
        its errors)."""
        return self.heard_lines() + self.conclusion_lines()

    def conclusion_lines(self) -> list[str]:
        """What the probe concludes: the advice, the firmware and its config lines, the
        lights."""
        out: list[str] = []
        failure = None if self.error is None else self.error.failure
        not_opened = failure is ProbeFailure.PORT_NOT_OPENED and not self.heard
        if not_opened and self.not_serial:
            # a file, a folder or /dev/null: "check the dome is plugged in" sent a user to the
            # hardware when the path given was the mistake
            out.append(
                f"{self.port} {self.not_serial}: it is not a serial port, so no firmware was "
                "asked. "
                "Give the dome's serial port (ls /dev/ttyACM* /dev/ttyUSB* /dev/serial/by-id/; "
                "on Windows COM3 ...)."
            )
        elif failure is ProbeFailure.PORT_FAILED and not self.heard:
            # it opened, then failed before its first listen was over (a USB adapter pulled
            # out, another program taking the port): "could not be opened" contradicted the
            # error above it
            out.append(
                "The port opened but failed before any firmware answered, so no firmware was "
                "identified. Check that the dome's cable is plugged in and that no other "
                "program uses the port, then probe again."
            )
        elif not_opened and self.permission_denied:
            # there, but not this user's: "check that the dome is plugged in" had followed the
            # error's advice to join the device's group
            out.append(
                "The port is there but this user may not open it, so no firmware was asked. "
                "Do as the error says (join the device's group, log out and in again), then "
                "probe again."
            )
        elif not_opened and self.port_held:
            # held by another program: "check the port's name, that the dome is plugged in"
            # sent a user to the cable of a dome another rti-rig was driving
            out.append(
                "Another program holds the port (another rti-rig's check or session on this "
                "dome, or a serial monitor), so no firmware was asked and nothing was sent. "
                "Let it finish or stop it (Ctrl-C in its terminal; `fuser "
                f"{self.port}` names it on Linux), then probe again."
            )
        elif not_opened:
            # the port never opened: nothing was asked, so nothing can be concluded about a
            # firmware (it had gone on to advise setting a profile for a port that is not there)
            out.append(
                "The port could not be opened, so no firmware was asked. Check the port's name "
                "(ls /dev/ttyACM* /dev/ttyUSB*; on Windows COM3 ...), that the dome is plugged "
                "in and powered, and that no other program holds the port."
            )
        elif self.profile is None:
            out.append(
                "No known dome firmware answered. Domes that never answer (hadrian2/RTI_Dome) "
                'cannot be identified by probing: set profile = "rti-dome-m" yourself, or '
                "describe the firmware (docs/domes.md). A nichlock board set to 300 baud in its "
                'settings menu is not listened for: profile = "nichlock" with baudrate = 300. '
                "If this is a servo arm's port (Dynamixel servos), silence is all probe can "
                "hear there: servos answer only their own packets, which probe does not send "
                "(their bytes could be commands to a dome); for an arm, run rti-rig check on "
                "its rig config."
            )
        elif self.unusable is not None:
            out.append(
                f"Found: {self.profile}, but {self.unusable}, so rti-rig cannot use it as it "
                "is (the note below says what to change). Rig-config lines to use once it is "
                "changed:"
            )
            out += ["  " + line for line in self.config_lines()]
        else:
            out.append(f"Found: {self.profile}. Rig-config lines to use:")
            out += ["  " + line for line in self.config_lines()]
            out += self._next_lines()
        out.append(f"Lights: {self.lights}")
        if self.note:
            out.append(f"Note: {self.note}")
        return out

    def _next_lines(self) -> list[str]:
        """What to do with the lines of a firmware found usable: the LED count where the
        firmware reports none, and the check to run (unless the note already ends in it).

        Why: only the own protocols' notes named a check; for the Nab sketch, minirti,
        nichlock, RTIPy and the others the probe ended on its lines, and those lines pasted
        into the example config were refused at load for ``led_count`` (the profile's 64 or
        126 against the 48 LEDs of the config's .lp): one round trip more per firmware."""
        from rti_rig.drivers.led_dome.dome_profiles import max_led_count

        out = []
        most = None if self.profile is None else max_led_count(self.profile)
        if most is not None:
            out.append(
                f"This firmware does not report how many LEDs it drives (at most {most}): "
                "under [dome.serial.protocol] add led_count = the LEDs wired, as many as the "
                "[dome] layout lists (the config is refused at load until they agree)."
            )
        check = self.check_command()
        if check in (self.note or ""):
            return out
        if self.rig:
            out.append(f"Next: put these lines in {shell_word(self.rig)}, then run {check}")
        else:
            out.append(
                "Next: put these lines in your rig config, then run rti-rig check YOUR-RIG.toml "
                "(probe --rig YOUR-RIG.toml prints that command for your config, to paste)"
            )
        return out


class ProbeStopped(Exception):
    """The probe was stopped (Ctrl-C, SIGTERM) and its teardown done: ``result`` holds what was
    heard, the firmware if one was found, and in ``lights`` what is known of the lights."""

    def __init__(self, stop: EmergencyStop, result: ProbeResult) -> None:
        super().__init__(str(stop))
        self.why, self.result = str(stop), result
        #: the signal the stop came from: the exit code is decided on it
        self.signum = stop.signum


# What the probe knows of the Nab sketch is read from its profile (``nab_rti_v1``), so that
# a fix there (a rate, a reply's words) reaches the probe too: they had been written out here.

#: The command a probed port was given to, said again with the ports present where it is
#: missing (it had been told to "set that port in the rig config", which probe takes none of).
PROBE_COMMAND = "rti-rig probe"


#: The Nab sketch's profile name, as a rig config names it.
_NAB_NAME: str = nab.SPEC["name"]

#: The rate the Nab sketch speaks: a stop on a port open at it listens for the sketch's boot.
_NAB_BAUD: int = nab.SPEC["baudrate"]

#: The sketch's all-off command, and its answer.
_NAB_ALL_OFF: bytes = nab.ALL_OFF["send"].encode("ascii")
_NAB_OFF_SAYS = re.compile(nab.ALL_OFF["reply"]["pattern"])

#: Its boot banner (printed by ``setup()``, with every LED lit), and its answer to a code it
#: does not know.
_NAB_BANNER = re.compile(nab.SPEC["reset_pattern"])
_NAB_UNKNOWN_CODE = re.compile(nab.SPEC["error_pattern"])

#: The end of its boot banner: the sketch is ready for commands.
_NAB_READY = re.compile(nab.SPEC["ready_pattern"])

#: Its answer to its all-on, which ``setup()`` prints too, as every LED lights at boot.
_NAB_ALL_ON = re.compile(nab.ALL_ON_REPLY_PATTERN)

#: The Nab sketch's boot banner, its answer to its all-on and to a code it does not know: each
#: means it booted, lit.
_NAB_SAYS = (_NAB_BANNER, _NAB_ALL_ON, _NAB_UNKNOWN_CODE)

#: The lights of a probe stopped before any firmware answered, once it opened the port.
STOPPED_UNANSWERED = (
    "the probe was stopped before a firmware answered: nothing that lights an LED was sent, but "
    "opening the port resets a board like an Arduino, which then lights whatever its firmware "
    "lights at boot (the Nab sketch: every LED): look at the dome"
)


def _exchange(
    result: ProbeResult,
    what: str,
    baud: int,
    wait_s: float,
    send: bytes,
    listen_s: float,
    tries: _For | None = None,
    more: tuple[_Then, ...] = (),
) -> str:
    """Open at ``baud``, wait ``wait_s`` (collecting the banner), send, listen; all text heard,
    also added to ``result.heard`` under ``what``. ``tries`` is told to
    :attr:`ProbeResult.on_try` with ``what``. Each of ``more`` is then sent on the same open
    port (no reset between), told as it begins and heard under its own label, unless an
    answer came first (:func:`_settled`).

    Each wait and listen ends as soon as what was heard is an answer that names a firmware
    completely (:func:`_answered`: a whole banner, a whole reply), and nothing is sent after
    a banner that already did: every listen had run its whole window, 2.6 s after a Nab
    banner over in 2 s. Silence, garbage at another rate or a banner still arriving is listened
    to for the whole window, which covers the firmwares' bootloaders and banners.

    A probe met by silence is sent once more on the same open port (every probe is harmless
    to the firmwares known, and none resets a board when it is repeated): one reply lost on
    the line, an Elexol board's ``USB I/O 24R1`` to ``?``, had made the probe say that no
    known firmware answered, where a session's driver resends the same command. Stopped
    (:class:`EmergencyStop`) with the port open, the stop's teardown runs on it
    (:func:`_stopped_on_open_port`), then :class:`ProbeStopped` is raised.

    At the Nab sketch's rate, a text that shows the sketch (its banner, its all-on, its answer
    to an unknown code) names it and has its all-off sent on this port before it is closed
    (:func:`_nab_off_on_open_port`): the board booted lit, and reopening the port for the
    all-off reset it once more."""
    if result.on_try is not None:
        result.on_try(what, "" if tries is None else tries.value)
    t = SerialTransport(result.port, baud, given_to=PROBE_COMMAND)
    result.openings += 1
    # the bytes are collected here as they come, not when a listen returns: a stop inside a
    # listen had lost all it heard (a Nab banner already in, then "stopped before a firmware
    # answered" and no all-off, the dome left lit)
    heard = bytearray()
    #: the label of the probe now on the port, and where its part of ``heard`` begins
    saying, said_from = what, 0
    opened = time.monotonic()
    # the opening is inside the try whose handler tears a stop down on the open port: a stop
    # landing once the port had opened, before that try began (as the opening's time was
    # read), escaped with the port still open and locked; the teardown then opened it again,
    # "another program holds it", and a Nab dome was left lit
    try:
        try:
            t.open()
        except TransportError as exc:
            held = isinstance(exc, PortHeldError)
            raise _PortNotOpened(str(exc), errno=exc.errno, held=held) from exc
        except EmergencyStop as exc:
            if not t.is_open:
                # inside pyserial's open, which closes the port as the stop goes through: the
                # opening may have reset the board all the same (the Nab sketch then boots lit)
                _stopped_inside_opening(result, t, wait_s)
                raise ProbeStopped(exc, result) from None
            # held over the opening (the transport's hold) and raised once the port was open:
            # the port is ours, at ``baud``; its teardown is below, as for a stop in the
            # listen. Taken for a stop inside the opening, the port was opened again while
            # this one still held its lock ("another program holds it"), and the Nab dome was
            # left lit (a SIGTERM sent as the board reset, on a loaded machine, lands there)
            raise
        opened = time.monotonic()
        _listen(t, wait_s, into=heard, done=_answered)
        reply: str | None = None  # the last probe's reply, once one was sent
        wrote = opened
        steps = [_Then(what, send, listen_s), *more]  # the first's ``tries`` told above
        for n, step in enumerate(steps):
            if not step.send or _settled(heard.decode("latin-1"), reply):
                break  # an answer came (or a banner began): nothing more is sent
            if n:
                # the next probe on this open port, told as it begins (the telling never waits
                # on output: a board may be lit meanwhile, see the CLI's ``trying``)
                if result.on_try is not None:
                    result.on_try(step.what, "" if step.tries is None else step.tries.value)
                left = max(opened + step.not_before_s, wrote + step.quiet_s) - time.monotonic()
                if left > 0:
                    _listen(t, left, into=heard, done=_answered)
                # what came before it is sent is said under the probe before it, the last
                # sent: RTIPy answers once 1 s of silence ends a command, so its answer to the
                # mask and '<9>' came in the wait before 'T,0,0,0' and had been shown as what
                # 'T,0,0,0' heard; a probe never sent (an answer came first) heard nothing
                if _settled(heard.decode("latin-1"), reply):
                    break
                result.heard.append(Heard(saying, baud, heard[said_from:].decode("latin-1")))
                saying, said_from = step.what, len(heard)
            t.write(step.send)
            wrote, asked = time.monotonic(), len(heard)

            def replied(text: str, asked: int = asked) -> bool:
                return _answered(text, text[asked:])

            _listen(t, step.listen_s, into=heard, done=replied)
            if len(heard) == asked:
                t.write(step.send)
                wrote = time.monotonic()
                _listen(t, step.listen_s, into=heard, done=replied)
            reply = heard[asked:].decode("latin-1")
        text = heard.decode("latin-1")
        result.heard.append(Heard(saying, baud, heard[said_from:].decode("latin-1")))
        if baud == _NAB_BAUD and any(says.search(text) for says in _NAB_SAYS):
            # the sketch, heard at its rate, booted lit: switched off on this port, which is
            # open; the probe had closed it and opened it again for the all-off, a second
            # reset (every LED lit once more, its boot waited out again, ~2 s)
            _nab_off_on_open_port(result, t, opened + _nab_boot_s(wait_s), bytearray(heard))
    except (ProbeStopped, _PortNotOpened):
        # its teardown done (or none due: the port never opened), on this port or another
        t.close()
        raise
    except EmergencyStop as exc:
        stopped_in = heard[said_from:].decode("latin-1")
        result.heard.append(Heard(f"{saying} (stopped)", baud, stopped_in))
        try:
            if result.lights_state is not LightsState.OFF_ACKNOWLEDGED:
                # (acknowledged: on this very port, the probe returning once it is, and no
                # opening since to light it again)
                _stopped_on_open_port(result, t, baud, opened, wait_s, heard.decode("latin-1"))
        except TransportError as failed:
            _teardown_failed(result, failed)
        finally:
            t.close()  # its all-off sent on it (closing resets no board; opening does)
        raise ProbeStopped(exc, result) from None
    except BaseException:
        t.close()
        raise
    try:
        t.close()
    except EmergencyStop:
        # the stop landed in the closing, what was heard kept in ``result.heard``: a firmware
        # it shows is named before the teardown (:func:`_stopped_between_ports`) decides
        _another_firmware_found(result, text, baud)
        raise
    return text


def _another_firmware_found(result: ProbeResult, text: str, baud: int) -> bool:
    """Name a firmware other than the Nab sketch if ``text`` (heard at ``baud``) shows it
    (nichlock's banner, the Elexol board's answer); True if one was named.

    Asked before a stop's teardown reopens the port to switch a Nab board off: a nichlock board
    whose banner was heard had been reset once more and told "stopped before a firmware
    answered"."""
    if _nichlock_found(result, text, baud):
        return True
    if _ELEXOL_SAYS in text:
        result.profile, result.baudrate = "elexol-24r1", 38400
        return True
    return _own_protocol_found(result, text, baud)


def _stopped_on_open_port(
    result: ProbeResult,
    t: SerialTransport,
    baud: int,
    opened: float,
    wait_s: float,
    heard: str = "",
) -> None:
    """The teardown of a probe stopped with ``t`` open at ``baud`` since ``opened``
    (monotonic), having heard ``heard`` on it: at the Nab sketch's rate, the rest of its boot
    window (:func:`_nab_boot_s`) is listened out on this port, until its banner is over, and a
    sketch that booted, lit, is sent its all-off here (reopening would reset it, lit again).

    At another rate, a port whose opening resets the board is closed and opened again at the
    sketch's rate (:func:`_reopened_at_nab_rate`): the sketch's board resets at every opening,
    whatever its rate, and boots at its own rate with every LED lit, heard at this one as
    nothing or garbage (it had been left so under "look at the dome"). Otherwise nothing that
    lights was sent, but an opening may have reset a board that boots lit once the probe is
    gone. A firmware other than the sketch shown in ``heard`` (nichlock's banner) is named and
    the port is not reopened: it answered, and another opening would only reset it."""
    if _another_firmware_found(result, heard, baud):
        return
    if baud == _NAB_BAUD:
        boot = bytearray(heard.encode("latin-1"))
        _listen_out_nab_boot(t, opened + _nab_boot_s(wait_s), boot)
        text = boot[len(heard) :].decode("latin-1")
        result.heard.append(Heard("listening out the board's boot", baud, text))
        whole = boot.decode("latin-1")  # a banner cut in two by the stop is still one banner
        if _nab_heard(result) or any(says.search(whole) for says in _NAB_SAYS):
            result.profile, result.baudrate = _NAB_NAME, _NAB_BAUD
            _nab_off(result, t)
            return
    elif t.resets_on_open:
        t.close()
        _reopened_at_nab_rate(result, wait_s)
        return
    _say_lights(result, LightsState.STOPPED_UNANSWERED)


def _nab_boot_s(wait_s: float) -> float:
    """How long a stop's teardown listens for the Nab sketch's boot after an opening: the
    probe's own listen, or the boot time the sketch's profile allows (``boot_wait_s``) if
    longer. A board slower to boot than the probe's listen is not heard by it, but it is lit
    all the same once it boots, and the teardown is the last chance to switch it off."""
    return max(wait_s, float(nab.SPEC["boot_wait_s"]))


def _nab_heard(result: ProbeResult) -> bool:
    """Some probe heard the Nab sketch (its banner, its answer to its all-on or to an unknown
    code): the board booted, and it boots with every LED on."""
    return any(says.search(heard.text) for heard in result.heard for says in _NAB_SAYS)


def _stopped_inside_opening(result: ProbeResult, cut: SerialTransport, wait_s: float) -> None:
    """The teardown of a probe stopped inside the opening of ``cut`` (not open: pyserial closes
    the port as the stop goes through). As ``check`` and ``run`` do after such a stop
    (``DomePolicy._reopen_cut_short_port``), a port whose opening may reset the board
    (``resets_on_open``) is opened again (:func:`_reopened_at_nab_rate`), at the Nab sketch's
    rate whatever the rate of the opening cut short: its board resets at every opening, and
    boots lit at its own rate (only a stop in a 9600-baud opening had reopened it; after one at
    115200, 19200 or 2400 the dome was left lit under "look at the dome"). A further signal is
    not raised (the command's handler raises only the first)."""
    if not cut.resets_on_open:
        _say_lights(result, LightsState.STOPPED_UNANSWERED)
        return
    _reopened_at_nab_rate(result, wait_s)


def _reopened_at_nab_rate(result: ProbeResult, wait_s: float) -> None:
    """Open the port again at the Nab sketch's rate after a stop (the opening resets the board
    once more: a Nab board boots lit either way) and do the stop's teardown on it
    (:func:`_stopped_on_open_port`): its boot listened out, its all-off sent if it is the
    sketch. A port that fails meanwhile is said in ``result``."""
    t = SerialTransport(result.port, _NAB_BAUD, given_to=PROBE_COMMAND)
    result.openings += 1
    try:
        t.open()
        _stopped_on_open_port(result, t, _NAB_BAUD, time.monotonic(), wait_s)
    except TransportError as failed:
        _teardown_failed(result, failed)
    finally:
        t.close()


def _teardown_failed(result: ProbeResult, failed: TransportError) -> None:
    """Say a port that failed during a stop's teardown: a board named as the Nab sketch
    booted lit and its all-off was not acknowledged, sent or not (:func:`_nab_not_off`: it may
    be lit); else the dome's state is not known. The sketch's case had been told "the dome's
    state is not known" once its all-off was sent on the port the stop found open."""
    result.error = ProbeError(ProbeFailure.PORT_FAILED, str(failed))
    if result.profile == _NAB_NAME and result.lights_state is not LightsState.OFF_ACKNOWLEDGED:
        _nab_not_off(result, failed)
    else:
        _say_lights(result, LightsState.PORT_FAILED_IN_STOP, _stop_failed(failed))


def _listen(
    t: SerialTransport,
    seconds: float,
    until: re.Pattern[str] | None = None,
    into: bytearray | None = None,
    done: Callable[[str], bool] | None = None,
) -> bytes:
    """All ``t`` sends for ``seconds``, or until what it sent matches ``until`` (an
    acknowledgement: no use listening on, and a stop would only find the probe still
    listening). ``until`` is matched against ``into`` when it is given (the caller's whole
    text: a ready line that a stop cut in two is still seen), else against this listen's bytes;
    ``done`` is asked of the same text, and ends the listen when it says True.

    Each read is also appended to ``into`` as it comes, so that a caller stopped inside the
    listen (:class:`EmergencyStop` raised from a read) still has what was heard: returned only
    at the end, a banner already received was lost with the stop."""
    out = bytearray()
    end = time.monotonic() + seconds
    while (left := end - time.monotonic()) > 0:
        data = t.read(min(left, 0.1))
        out += data
        if into is not None:
            into += data
        if until is None and done is None:
            continue
        seen = (out if into is None else into).decode("latin-1")
        if until is not None and until.search(seen):
            break
        if done is not None and done(seen):
            break
    return bytes(out)


def _nab_found(result: ProbeResult, wait: float) -> ProbeResult:
    """The Nab sketch was heard but not switched off on the port it was heard on (a stop's
    teardown with no port open, or the sketch heard at another rate than its own): open the
    port at its rate (a reset: it boots lit again) and switch it off there
    (:func:`_nab_off_on_open_port`).

    A stop held over the opening (the transport's hold) is finished on this port, as a stop in
    the boot listen is: left open, it had been reopened by the caller's teardown while still
    locked, and the dome left lit."""
    result.profile, result.baudrate = _NAB_NAME, _NAB_BAUD
    t = SerialTransport(result.port, _NAB_BAUD, given_to=PROBE_COMMAND)
    result.openings += 1
    stop: EmergencyStop | None = None
    try:
        t.open()
    except EmergencyStop as exc:
        if not t.is_open:
            raise  # cut short inside pyserial's open (the port closed): the caller reopens it
        stop = exc
    try:
        _nab_off_on_open_port(result, t, time.monotonic() + _nab_boot_s(wait), bytearray(), stop)
    finally:
        t.close()
    return result


def _nab_off_on_open_port(
    result: ProbeResult,
    t: SerialTransport,
    deadline: float,
    booted: bytearray,
    stop: EmergencyStop | None = None,
) -> None:
    """Switch off the Nab sketch on ``t``, open at its rate: it boots with every LED on.
    ``booted`` holds what this opening has heard so far; the rest of the sketch's boot is
    listened to first, until its banner is over (its ready line, ``ready_pattern``) or an
    answer to a code shows it running, up to ``deadline`` (monotonic: the opening plus the boot
    time its profile allows, :func:`_nab_boot_s`); after a fixed wait the all-off had reached
    a board slower to boot (3.3 to 4 s) still in its bootloader, which drops what it receives,
    and the dome was left lit. The port is left open: its owner closes it.

    A stop (:class:`EmergencyStop`; ``stop``, one already held over the opening), in the boot
    listen or in the all-off itself, is held until the all-off is through on this same open
    port, then raised as :class:`ProbeStopped`: a stop mid all-off had escaped to the probe's
    teardown, which opened the port again (a reset: every LED lit once more) to send the
    all-off a second time. A port that fails after such a stop is said, with the lights, in
    :class:`ProbeStopped` (it had ended as a probe that succeeded, exit 0, "Found:
    nab-rti-v1"); one that fails with no stop is raised (the probe's own handler says it: the
    dome may be lit, exit 1)."""
    result.profile, result.baudrate = _NAB_NAME, _NAB_BAUD
    before = len(booted)
    listened = False
    try:
        try:
            if stop is not None:
                raise stop  # the teardown below: the rest of the boot, then the all-off
            # the board resets as the port opens: its bootloader, then its banner
            listened = not _nab_running(booted.decode("latin-1"))
            _listen_out_nab_boot(t, deadline, booted)
        except EmergencyStop as exc:
            # the teardown: the rest of the boot, so that the all-off reaches a booted board
            stop, listened = exc, True
            _listen_out_nab_boot(t, deadline, booted)
        if listened:
            rest = booted[before:].decode("latin-1")
            result.heard.append(Heard(f"the board's boot at {_NAB_BAUD} baud", _NAB_BAUD, rest))
        try:
            _nab_off(result, t)
        except EmergencyStop as exc:
            # the first stop came during the all-off (the command's handler raises only the
            # first): it is finished here, where reopening would reset the board, lit again
            stop = exc
            _nab_off(result, t)
    except TransportError as exc:
        if stop is None:
            raise  # the probe's own handler says it (the dome may be lit; exit 1)
        result.error = ProbeError(ProbeFailure.PORT_FAILED, str(exc))
        _nab_not_off(result, exc)
        raise ProbeStopped(stop, result) from None
    if stop is not None:
        raise ProbeStopped(stop, result) from None


def _listen_out_nab_boot(t: SerialTransport, deadline: float, booted: bytearray) -> None:
    """Listen on ``t`` (open at the Nab sketch's rate) into ``booted`` (all this opening heard)
    until it shows the sketch past its boot (:func:`_nab_running`: its banner's last line, or
    its answer to a code) or ``deadline`` (monotonic) passes; at once if it already does.

    The one listen both the switching-off (:func:`_nab_off_on_open_port`) and a stop's
    teardown (:func:`_stopped_on_open_port`) do before the sketch's all-off. The teardown's
    own copy waited for the banner's last line only: after the sketch's answer to ``<9>``
    (its banner over, or lost), it listened out the rest of the 4 s the profile allows a boot,
    for a line that had come or never would."""
    if _nab_running(booted.decode("latin-1")):
        return
    _listen(t, max(0.0, deadline - time.monotonic()), into=booted, done=_nab_running)


def _nab_running(text: str) -> bool:
    """``text``, heard since an opening, shows the Nab sketch past its boot: its banner over
    (its ready line) or its answer to a code it does not know (printed from ``loop()``)."""
    return bool(_NAB_READY.search(text) or _NAB_UNKNOWN_CODE.search(text))


def _nab_not_off(result: ProbeResult, exc: TransportError | None = None) -> None:
    """Say the lights of a Nab board (it booted, lit) whose port failed (``exc``) before its
    all-off was acknowledged: "sent, but not acknowledged" if ``<0>`` was written since the
    last opening (:attr:`ProbeResult.off_written_at_opening`), else "could NOT be sent". A
    port that failed in the listen after the write had been told "could NOT be sent"."""
    why = "" if exc is None else f" ({exc})"
    if result.off_written_at_opening and result.off_written_at_opening == result.openings:
        _say_lights(
            result,
            LightsState.OFF_SENT_PORT_FAILED,
            f"the sketch boots with every LED on and the all-off was sent, but not "
            f"acknowledged (the port failed{why}): the dome may still be lit; look at it, and "
            "switch it off at its power supply if it is",
        )
        return
    _say_lights(
        result,
        LightsState.OFF_NOT_SENT,
        f"the sketch boots with every LED on and the all-off could NOT be sent{why}: the "
        "dome may be fully lit; switch it off at its power supply",
    )


def _nab_off(result: ProbeResult, t: SerialTransport) -> None:
    """Send the Nab sketch's all-off ``<0>`` on ``t`` (open at its rate, the sketch booted) and
    say in ``result.lights`` whether it was acknowledged.

    Sent again on the same open port if unanswered (reopening it would reset the board, which
    lights every LED again): one lost reply, or a <0> the board missed, had ended the probe
    with "NOT acknowledged: check the dome", where a session resends it. Listening ends at the
    acknowledgement (it had gone on for the whole window). A stop meanwhile is raised from
    here: the caller, which holds the open port, finishes the all-off on it."""
    off = ""
    command = _NAB_ALL_OFF.decode("ascii")
    for what, listen_s in (
        (_ALL_OFF_SAID.format(command=command), 0.6),
        (_ALL_OFF_AGAIN_SAID.format(command=command), 1.2),
    ):
        t.write(_NAB_ALL_OFF)
        result.off_written_at_opening = result.openings
        off = _listen(t, listen_s, until=_NAB_OFF_SAYS).decode("latin-1")
        result.heard.append(Heard(what, t.baudrate, off))
        if _NAB_OFF_SAYS.search(off):
            break
    if _NAB_OFF_SAYS.search(off):
        if result.error is not None and result.error.failure is ProbeFailure.OFF_NOT_ACKNOWLEDGED:
            # a first all-off unanswered (its error said), this one acknowledged: decided on
            # the error's kind, not on how its words begin
            result.error = None
        _say_lights(result, LightsState.OFF_ACKNOWLEDGED)
        return
    _say_lights(result, LightsState.OFF_NOT_ACKNOWLEDGED)
    # a probe that leaves the lights unconfirmed is no success: it had exited 0 under
    # "Found: nab-rti-v1", the dome lit
    result.error = ProbeError(
        ProbeFailure.OFF_NOT_ACKNOWLEDGED,
        f"{_NOT_ACKNOWLEDGED} {command} (sent twice on {result.port}): the dome may be fully "
        "lit; look at it, and switch it off at its power supply if it is",
    )


#: How the error of an all-off the Nab sketch did not acknowledge begins (said only: whether
#: a later all-off clears it is decided on :attr:`ProbeError.failure`).
_NOT_ACKNOWLEDGED = "the Nab sketch did not acknowledge its all-off"

#: The labels of the Nab sketch's all-off and its resending, in the lines heard (said only).
_ALL_OFF_SAID = "all off {command}"
_ALL_OFF_AGAIN_SAID = "all off {command} again"

#: The label of a probe that only listens at a rate, in the lines heard (said only: the
#: teardown takes the rate from :attr:`Heard.baud`).
_LISTEN_SAID = "listen at {baud} baud"


def _stop_failed(failed: TransportError) -> str:
    """The lights of a probe whose port failed during a stop's teardown."""
    return (
        f"the port failed while the probe stopped ({failed}): the dome's state is not "
        "known; look at it"
    )


#: The words said of each state whose words take nothing from the case.
_LIGHTS_SAID: dict[LightsState, str] = {
    LightsState.NOTHING_LIT: "nothing was lit by the probe",
    LightsState.NEVER_OPENED: "nothing was lit by the probe: it never opened the port",
    LightsState.PORT_UNUSABLE: "the port could not be used; nothing was sent",
    LightsState.PORT_FAILED_UNANSWERED: (
        "the port failed once open, before a firmware answered: nothing that lights an LED "
        "was sent, but opening the port resets a board like an Arduino, which then lights "
        "whatever its firmware lights at boot (the Nab sketch: every LED): look at the dome"
    ),
    LightsState.STOPPED_UNANSWERED: STOPPED_UNANSWERED,
    LightsState.BOOTS_DARK: "the firmware boots with every LED off; nothing that lights was sent",
    LightsState.MASK_ACKNOWLEDGED: "the probe sent an all-off mask, acknowledged",
    LightsState.ZERO_SECONDS: "LED (0, 0) was asked for zero seconds: it stays dark",
    LightsState.OFF_ACKNOWLEDGED: (
        "the sketch boots with every LED on; all-off sent and acknowledged"
    ),
    LightsState.OFF_NOT_ACKNOWLEDGED: (
        "the sketch boots with every LED on; all-off sent twice but NOT acknowledged: check "
        "the dome"
    ),
}


def _say_lights(result: ProbeResult, state: LightsState, said: str | None = None) -> None:
    """Set what is known of the lights: ``state``, decided on, and the words said of it
    (``said``, for a state whose words take the case's details; else its words in
    :data:`_LIGHTS_SAID`). Both are set together, so that no line says lights the state does
    not hold."""
    result.lights_state = state
    result.lights = _LIGHTS_SAID[state] if said is None else said


def _unanswered_lights(wait: float) -> str:
    """What is known of the lights when no firmware answered: nothing lighting was sent, but
    an opening resets an Arduino, and a board that boots lit after the last listen is lit."""
    # a board that resets at every opening and is still in its bootloader when each listen
    # ends is heard by no probe; the Nab sketch then lights every LED as it boots, after the
    # probe had said only that nothing lighting was sent
    return (
        f"nothing that lights an LED was sent; but a board that resets when its port opens "
        f"(an Arduino) and takes longer than the {wait:g} s each probe listens to boot "
        "answers none of them, and lights whatever its firmware lights at boot once the "
        "probe has closed the port (the Nab sketch: every LED): look at the dome"
    )


#: What nichlock/rti's firmware prints, at whatever rate its EEPROM holds: its banner, the free
#: RAM (``m``) and its answer to a key it does not know (``arduino-program/src/main.cpp``).
_NICHLOCK_SAYS = (
    "Reflectance Transformation Imager Serial Interface",
    "RAM bytes remaining",
    "Did nothing; that key is not assigned",
)


#: What the Elexol 24R1 board answers to ``?``.
_ELEXOL_SAYS = "USB I/O 24R1"
#: The same, as the pattern a damaged answer is measured against (:func:`one_byte_off`).
_ELEXOL_REPLY = re.compile(re.escape(_ELEXOL_SAYS))


#: The rates besides 9600 and 115200 that nichlock's settings menu offers and the probe listens
#: at (its fifth, 300 baud, would need seconds for the banner alone: not tried).
NICHLOCK_OTHER_RATES = (19200, 2400)


def _nichlock_found(result: ProbeResult, text: str, baud: int) -> bool:
    """Name nichlock's firmware if ``text`` (heard at ``baud``) is its; True if it was.

    Checked after every probe, not only at 115200: its rate is stored in EEPROM (9600 on a
    board set so), and a 9600-baud board that was not recognised went on to RTIPy's
    ``T,0,0,0``, whose three ``0`` step it to its third LED, left lit under the words "nothing
    that lights an LED was sent".
    """
    if not any(words in text for words in _NICHLOCK_SAYS):
        return False
    result.profile, result.baudrate = "nichlock", baud
    _say_lights(result, LightsState.BOOTS_DARK)
    if "Starting Calibration" in text and "For help, press 'h'" not in text:
        # beginDisplay holds the boot in calTouch while the touch screen is uncalibrated: a
        # check then meets the calibration, not the prompt (it says so too)
        result.note = (
            "its boot waits in its touch-screen calibration (the screen is not calibrated): "
            "tap the two red circles on its display, or press 'c' in a serial terminal to skip "
            f"it this once ('s' to stop it for good), before {result.check_command()}"
        )
    return True


#: The boot banners of rti-rig's own protocols (docs/protocols/led-dome.md), as each profile
#: prints them with its options left at their defaults: ``READY <id> <version> <count>*HH``,
#: ``<READY,<id>,<version>,<count>>`` and the binary ``0xFF R D Y``. A default line may end in
#: CR LF (the protocol allows it; an Arduino sketch's ``Serial.println`` sends it): a pattern
#: wanting a bare LF had left such a board "No known dome firmware answered". A bare ``READY``
#: is taken only with its checksum (``READY*HH``): a sketch's "READY" alone names nothing.
_OWN_BANNERS = (
    ("default", re.compile(r"READY[ *][^\r\n]*\r?\n")),
    ("framed", re.compile(r"<READY(?:,[^<>\r\n]*)?>")),
    ("binary", re.compile("\xffRDY")),
)

#: What the probe cannot hear of each own profile, said with its config lines (each ends
#: "then run ", the check command following: :meth:`ProbeResult.check_command`).
_OWN_UNHEARD = {
    "framed": (
        "a framed board's other options (index_base, line_ending, the command codes) are not "
        "in its banner: set [dome.serial.framed] as its firmware's documentation says (the "
        "defaults are 0-based and no line ending), then run "
    ),
    "binary": (
        "a binary board's start_byte and index_base are not in its banner: set "
        "[dome.serial.binary] as its firmware's documentation says if they are not 0xA5 and 0, "
        "then run "
    ),
}


#: The last words of nichlock's boot, each of which nothing more of it follows until a key
#: comes: its prompt, and its touch-screen calibration (which holds the boot in it).
_NICHLOCK_BOOT_ENDS = ("For help, press 'h'", "Starting Calibration")

#: How long RTIPy's board takes to boot, by its profile: ``T,0,0,0`` is never sent sooner
#: after the opening. On the opening it shares with minirti's mask and the Nab sketch's
#: ``<9>`` it comes later all the same, after 1.5 s of the probe's silence
#: (:data:`_RTIPY_FRAME_S`): on a silent port the mask at 1.6 s (again at 2.1 s), ``<9>`` at
#: 2.6 s (again at 3.2 s), ``T,0,0,0`` at 4.7 s (again at 6.5 s), the last listen ending 8.3 s
#: from the opening. A slower board's banner (the Nab sketch's, up to the 4 s its profile
#: allows) is heard by those listens, and the whole text of the opening is what decides.
_RTIPY_BOOT_S = float(rtipy.SPEC["boot_wait_s"])

#: RTIPy's whole answer to the probe's ``T,0,0,0`` (printed with no line ending).
_RTIPY_SAYS = "I received: T,0,0,0 the instructionByte was: T"


def _answered(text: str, reply: str | None = None) -> bool:
    """``text`` (all a probe heard since the port opened; ``reply``, its part since the probe's
    bytes were sent, if they were) holds an answer that names a firmware completely, so that
    listening on can change nothing the probe decides: the Nab sketch's banner to its last
    line (``ready_pattern``) or its whole answer to an unknown code, nichlock's banner to its
    prompt or its calibration (whose note depends on which comes), a whole line of nichlock's
    answer to a key, the Elexol board's ``USB I/O 24R1``, minirti's acknowledgement (the byte
    ``0x01``, all the reply: once, or more than once read in one chunk), RTIPy's whole answer,
    or a whole boot banner of rti-rig's own protocols. Anything else (silence, bytes at another
    rate, a banner still arriving) is no answer yet: the listen runs on to its end."""
    if _NAB_READY.search(text) or _NAB_UNKNOWN_CODE.search(text):
        return True
    if "Reflectance Transformation Imager Serial Interface" in text:
        return any(words in text for words in _NICHLOCK_BOOT_ENDS)
    lines = text.split("\n")[:-1]  # the lines that ended
    if any(words in line for line in lines for words in _NICHLOCK_SAYS):
        return True
    if _ELEXOL_SAYS in text or _RTIPY_SAYS in text or _acknowledgements(reply):
        return True
    return _own_protocol(text) is not None


def _acknowledgements(reply: str | None) -> bool:
    """``reply`` is minirti's acknowledgement ``0x01`` and nothing else, one or more of them.

    Why more than one: a board whose acknowledgement came late (the one byte of an earlier
    mask, or one said twice) can be read in one chunk with the next: ``"\\x01\\x01"`` taken as no
    answer had the probes after it (``<9>``, ``T,0,0,0``) sent to a board that had answered."""
    return reply is not None and reply != "" and reply.strip("\x01") == ""


def _acknowledged_mask(result: ProbeResult, mask_at: int) -> bool:
    """minirti's acknowledgement ``0x01`` ends what its mask's probe heard (``mask_at``: its
    place in ``result.heard``; the probes sent after it on the same opening are said apart)."""
    return len(result.heard) > mask_at and result.heard[mask_at].text.endswith("\x01")


def _settled(text: str, reply: str | None) -> bool:
    """No further probe is sent on this opening: ``text`` (all heard since it opened; ``reply``,
    what the last probe sent on it heard) is an answer (:func:`_answered`), or shows the Nab
    sketch (a banner begun: its board booted lit, its all-off comes next, once its boot is
    over) or nichlock's firmware (whose keys the next probe's bytes would be)."""
    if _answered(text, reply):
        return True
    return any(says.search(text) for says in _NAB_SAYS) or any(
        words in text for words in _NICHLOCK_SAYS
    )


def _own_protocol(text: str) -> str | None:
    """The first boot banner of one of rti-rig's own protocols in ``text``, or None."""
    found = [(m.start(), m.group()) for _, pattern in _OWN_BANNERS if (m := pattern.search(text))]
    return min(found)[1] if found else None


def _own_protocol_found(result: ProbeResult, text: str, baud: int) -> bool:
    """Name rti-rig's own protocol (default, framed, binary) if ``text`` (heard at ``baud``
    once the port opened, nothing sent) holds its boot banner, decoded by the profile's codec;
    True if one was named.

    The probe knew only the firmwares of other projects: a board speaking the project's own
    protocol, which announces itself at every boot, had been told "No known dome firmware
    answered" with its ``READY`` line among the lines heard, and sent on to set
    ``profile = "rti-dome-m"``."""
    for profile, pattern in _OWN_BANNERS:
        match = pattern.search(text)
        if match is None:
            continue
        raw = match.group().encode("latin-1")
        codecs = {
            "default": (DefaultCodec(), DefaultCodec(checksum=False)),
            "framed": (FramedCodec(FramedSpec()),),
            "binary": (BinaryCodec(),),
        }[profile]
        for codec in codecs:
            reply, _ = codec.decode_reply(raw, None)
            if not isinstance(reply, Banner):
                continue
            result.profile, result.baudrate = profile, baud
            if isinstance(codec, DefaultCodec) and not codec.checksum:
                result.extra_lines = ["[dome.serial.default]", "checksum = false"]
            notes = []
            if reply.identity is not None:
                who = reply.identity
                notes.append(
                    f"it announced {who.firmware_id} {who.version} with {who.led_count} LEDs"
                )
            if profile in _OWN_UNHEARD:
                notes.append(_OWN_UNHEARD[profile] + result.check_command())
            result.note = "; ".join(notes) or None
            return True
        if (extra := _banner_extra_fields(profile, match.group())) is not None:
            fields, checksum = extra
            result.profile, result.baudrate = profile, baud
            if profile == "default" and not checksum:
                result.extra_lines = ["[dome.serial.default]", "checksum = false"]
            # no codec of the profile accepts it (tried above): the check would fail on it
            result.unusable = "its boot banner has fields after the LED count"
            result.note = (
                f"its banner {match.group().strip()!r} carries {len(fields)} field(s) more than "
                f"rti-rig's {profile} protocol's id, version and LED count "
                f"({', '.join(repr(f) for f in fields)}), which rti-rig reads as a damaged "
                "banner: end the firmware's banner at the LED count, as "
                f"docs/protocols/led-dome.md writes it, then run {result.check_command()}"
            )
            return True
    return False


def _banner_extra_fields(profile: str, banner: str) -> tuple[list[str], bool] | None:
    """The fields after the LED count of an own-protocol banner that otherwise reads (an id,
    a version and a whole number count after ``READY``), and whether it ended in a checksum;
    None for any other banner.

    Why: a board whose banner had one field more (a board revision, a build date) was told
    "No known dome firmware answered", its READY line among the lines heard, not named."""
    text = banner.strip()
    checksum = False
    if profile == "default":
        if re.search(r"\*[0-9A-F]{2}$", text):
            text, checksum = text[:-3], True
        fields = text.split(" ")
    elif profile == "framed":
        fields = text.strip("<>").split(",")
    else:
        return None
    if len(fields) <= 4 or fields[0] != "READY" or not fields[3].isdigit():
        return None
    return fields[4:], checksum


def probe(request: ProbeRequest, result: ProbeResult | None = None) -> ProbeResult:
    """Try the known firmwares on ``request.port``; see the module docstring for the order.

    ``result``, if given (for ``request.port``), is filled as the probe goes and returned: a
    caller whose stop lands after the probe returned, before it took the result, still has what
    the probe established of the lights (the command had said only "look at the dome's lights",
    after an all-off the board had acknowledged).

    Raises :class:`ProbeStopped` once a stop (:class:`EmergencyStop`) has had its teardown."""
    result = ProbeResult(request.port) if result is None else result
    try:
        return _probe(result, request.listen_s)
    except EmergencyStop as exc:  # stopped with no port open: a port's own is raised there
        _stopped_between_ports(result, request.listen_s)
        raise ProbeStopped(exc, result) from None


def _stopped_between_ports(result: ProbeResult, wait: float) -> None:
    """The teardown of a probe stopped with no port open (before the first, between two)."""
    if result.lights_state is LightsState.OFF_ACKNOWLEDGED:
        # its all-off was acknowledged, the stop coming as the port closed after it: reopening
        # would reset the board, lit once more, to switch it off again (``lights`` says it)
        return
    if result.profile == _NAB_NAME or (result.profile is None and _nab_heard(result)):
        # identified (or heard, the stop coming before it was named), lit at its boot, and
        # stopped before its all-off: sent now (the opening resets it, lit again, so the boot
        # is waited for as the probe waits for it); "stopped before a firmware answered" had
        # been said with the banner among the lines heard, the dome left lit
        try:
            _nab_found(result, wait)
        except TransportError as exc:
            result.error = ProbeError(ProbeFailure.PORT_FAILED, str(exc))
            _nab_not_off(result, exc)
    elif result.profile is not None or result.error is not None:
        # the probe had concluded (another firmware found, or the port failed), the stop coming
        # as it returned: its lights stand ("stopped before a firmware answered … look at the
        # dome" had replaced a found nichlock board's "boots with every LED off")
        return
    elif _heard_another_firmware(result):
        # its text was heard but not yet looked at, the stop coming as the probe read it:
        # named, its port not reopened (it answered; an opening would only reset it)
        return
    elif result.openings and SerialTransport(result.port, _NAB_BAUD).resets_on_open:
        # a port opened, each opening a reset after which a Nab board boots lit at its own
        # rate, and nothing concluded: opened again at that rate, as after a stop inside an
        # opening (a stop between two ports had left such a board lit under "look at the dome")
        _reopened_at_nab_rate(result, wait)
    elif result.openings:
        _say_lights(result, LightsState.STOPPED_UNANSWERED)
    else:
        _say_lights(result, LightsState.NEVER_OPENED)


def _heard_another_firmware(result: ProbeResult) -> bool:
    """Some probe's text in ``result.heard`` shows a firmware other than the Nab sketch
    (:func:`_another_firmware_found`, at the rate that probe used), which is then named."""
    return any(_another_firmware_found(result, heard.text, heard.baud) for heard in result.heard)


class _For(Enum):
    """The firmwares a probe is for, as :attr:`ProbeResult.on_try` is told them (said only).
    Each probe passes its own to :func:`_exchange`: the words had been looked up by the probe's
    label, so rewording a label (or a rate) silently said no firmware at all."""

    NAB_NICHLOCK_OWN = "the Nab sketch (RTI v1.0), nichlock, rti-rig's own protocols"
    NICHLOCK_OWN = "nichlock, rti-rig's own protocols"
    NICHLOCK = "nichlock"
    ELEXOL = "Elexol 24R1"
    NAB = "the Nab sketch (RTI v1.0)"
    MINIRTI = "minirti"
    RTIPY = "RTIPy"


@dataclass(frozen=True)
class _Then:
    """A further probe sent on the port an exchange opened, after its first (:func:`_exchange`):
    no reopening between them, so no reset and no bootloader waited out again (each opening of
    an Arduino-style board had cost its boot, ~2 s, three times at 9600)."""

    #: What it is, as printed ("'<9>' (an unknown code) at 9600 baud").
    what: str
    send: bytes
    #: How long its reply is listened for (twice if met by silence: it is sent once more).
    listen_s: float
    #: The firmwares it is for (told as it begins; None: the first, told by its caller).
    tries: _For | None = None
    #: It is not sent before this many seconds since the opening (a bootloader, a banner).
    not_before_s: float = 0.0
    #: Seconds of silence from the probe before it is sent: RTIPy takes what arrives before
    #: 1 s of silence as one command, so ``T,0,0,0`` sent sooner after the probes before it
    #: would be part of their command, not a ``T``.
    quiet_s: float = 0.0


#: How long minirti's host waits after opening the port before its first mask.
_MINIRTI_BOOT_S = 1.6

#: The label of the Nab sketch's unknown-code probe (said only).
_UNKNOWN_CODE_SAID = f"'<9>' (an unknown code) at {_NAB_BAUD} baud"

#: The silence RTIPy's sketch needs to end a command (``Serial.readString``'s 1 s), with room
#: for a loaded machine's or a USB link's delay: ``T,0,0,0`` after other probes on one open.
_RTIPY_FRAME_S = 1.5


def _probe(result: ProbeResult, wait: float) -> ProbeResult:
    """:func:`probe`'s sequence of probes."""
    try:
        said = _LISTEN_SAID.format(baud=9600)
        text = _exchange(result, said, 9600, wait, b"", 0, _For.NAB_NICHLOCK_OWN)
        if result.profile == _NAB_NAME:
            return result  # heard at its rate, and switched off on that port (_exchange)
        if _nichlock_found(result, text, 9600):
            return result
        own_at_9600 = _own_protocol(text)
        said = _LISTEN_SAID.format(baud=115200)
        text = _exchange(result, said, 115200, wait, b"", 0, _For.NICHLOCK_OWN)
        if _nichlock_found(result, text, 115200):
            return result
        # rti-rig's own protocols announce themselves at boot: heard at both rates, the link
        # ignores the rate (a board's native USB, a pty), and 115200 is the profiles' own
        if _own_protocol_found(result, text, 115200) or (
            own_at_9600 is not None and _own_protocol_found(result, own_at_9600, 9600)
        ):
            return result
        # nichlock's settings menu (``a``, ``2``) stores 19200 or 2400 too, taken at its next
        # boot: listened for before anything is sent, since bytes at another rate reach such a
        # board as keys of its menus (a board set so had been "No known dome firmware")
        for rate in NICHLOCK_OTHER_RATES:
            said = _LISTEN_SAID.format(baud=rate)
            text = _exchange(result, said, rate, wait, b"", 0, _For.NICHLOCK)
            if _nichlock_found(result, text, rate) or _own_protocol_found(result, text, rate):
                return result
        text = _exchange(result, "'?' at 38400 baud", 38400, 0.2, b"?", 0.5, _For.ELEXOL)
        damaged = _ELEXOL_SAYS not in text and one_byte_off(_ELEXOL_REPLY, text)
        if damaged:
            # its answer with one byte damaged on the line: asked again (``?`` lights nothing;
            # the board's FTDI port does not reset on opening), not "no known firmware"
            said = "'?' again at 38400 baud (the answer came with one byte damaged)"
            text = _exchange(result, said, 38400, 0.2, b"?", 0.5, _For.ELEXOL)
        if _ELEXOL_SAYS in text:
            result.profile, result.baudrate = "elexol-24r1", 38400
            if damaged:
                result.note = (
                    "its first answer came with one byte damaged on the line; if that recurs, "
                    "check the USB cable and hub (the session resends what was garbled)"
                )
            return result
        said = "'m' (free RAM) at 115200 baud"
        text = _exchange(result, said, 115200, wait, b"m", 0.5, _For.NICHLOCK)
        if _nichlock_found(result, text, 115200):
            return result
        # minirti's mask, the Nab sketch's unknown code and RTIPy's T,0,0,0, on one opening
        # at 9600 (each had its own: three resets, each boot waited out): the mask first, a
        # minirti board's only published command, 1.6 s after the opening (its host waits
        # 1.5 s), so that it is sent nothing else before it; bytes outside <...> are nothing
        # to the Nab sketch, and the probe's bytes are all one harmless command to RTIPy,
        # whose T,0,0,0 goes last, after the silence that ends a command there
        mask_at = len(result.heard)
        text = _exchange(
            result,
            "0x42 + empty mask at 9600 baud",
            9600,
            min(wait, _MINIRTI_BOOT_S),
            b"\x42" + bytes(8),
            0.5,
            _For.MINIRTI,
            (
                _Then(_UNKNOWN_CODE_SAID, b"<9>", 0.6, _For.NAB, not_before_s=wait),
                _Then(
                    "'T,0,0,0' at 9600 baud",
                    b"T,0,0,0",
                    1.8,
                    _For.RTIPY,
                    not_before_s=_RTIPY_BOOT_S,
                    quiet_s=_RTIPY_FRAME_S,
                ),
            ),
        )
        if result.profile == _NAB_NAME:
            return result  # its banner or answer heard at its rate, switched off there
        if _nichlock_found(result, text, 9600):
            return result
        if _acknowledged_mask(result, mask_at):
            result.profile, result.baudrate = "minirti", 9600
            _say_lights(result, LightsState.MASK_ACKNOWLEDGED)
            return result
        if _RTIPY_SAYS in text:
            result.profile, result.baudrate = "rtipy", 9600
            _say_lights(result, LightsState.ZERO_SECONDS)
            return result
        if _nab_heard(result):
            # a Nab board slower to boot than a probe's listen (up to the 4 s its profile
            # allows) is first heard by a later probe's longer listen (switched off there when
            # at its rate): its banner had been shown among the lines heard under "No known
            # dome firmware answered", the dome left lit
            return _nab_found(result, wait)
        _say_lights(result, LightsState.UNANSWERED, _unanswered_lights(wait))
    except TransportError as exc:
        opening = isinstance(exc, _PortNotOpened)
        result.error = ProbeError(
            ProbeFailure.PORT_NOT_OPENED if opening else ProbeFailure.PORT_FAILED, str(exc)
        )
        if result.profile == _NAB_NAME:
            # it answered, so it booted, and it boots with every LED on
            _nab_not_off(result)
        elif result.heard:
            sent = ", ".join(heard.label for heard in result.heard)
            _say_lights(
                result,
                LightsState.PORT_FAILED_AFTER_PROBES,
                f"the port failed after these probes ({sent}); none of them lights an LED on "
                "the firmwares known, but the dome's state is not known",
            )
        else:
            # a port that opened had reset the board all the same: "nothing was sent" of it
            # had read as nothing lit, of a Nab sketch that boots with every LED on
            _say_lights(
                result,
                LightsState.PORT_UNUSABLE if opening else LightsState.PORT_FAILED_UNANSWERED,
            )
            # what the path is, from its opening's failure (a read's failure says nothing of it)
            result.not_serial = _not_a_serial_port(result.port, exc) if opening else None
            result.permission_denied = opening and exc.errno == errno.EACCES
            result.port_held = isinstance(exc, _PortNotOpened) and exc.held
    return result


def _not_a_serial_port(port: str, error: TransportError) -> str | None:
    """How ``port``, which failed to open with ``error``, is no serial port (``"is a regular
    file"``, ``"is a device but not a terminal"`` …), or None when it may be one (missing,
    held, a URL, a name the system does not map to a path such as COM3).

    Judged from the path after the failure, never by opening it again: opening a real serial
    port resets an Arduino. A character device that refused the terminal settings is a device
    but not a serial one; the system's number for the failure (``error.errno``) says so:
    ENOTTY ("Inappropriate ioctl for device": /dev/null, /dev/zero), EINVAL (/dev/random,
    which had been told to check that the dome is plugged in). EIO there is a serial port whose
    device went away as it opened. Decided from the number, not from the message's words (it
    had looked for "Inappropriate ioctl" and pyserial's "Could not configure port" in the
    text, which a pyserial release or a translated strerror would change)."""
    try:
        mode = os.stat(port).st_mode
    except (OSError, ValueError):
        return None
    if stat.S_ISREG(mode):
        return "is a regular file"
    if stat.S_ISDIR(mode):
        return "is a folder"
    if not stat.S_ISCHR(mode):
        return "is not a device file"
    if error.errno in _NOT_A_TERMINAL:
        return "is a device but not a terminal"
    return None


#: The system's numbers for a character device that refuses a terminal's settings.
_NOT_A_TERMINAL = frozenset({errno.ENOTTY, errno.EINVAL})


def _port_line(port: str) -> str:
    """The ``port = ...`` line for ``port`` as TOML reads it back: a basic string, escaped.

    Why: the line was written ``port = "{port}"`` as it was, so a Windows port by its device
    path (``\\\\.\\COM10``, what COM10 and above need) made a line TOML refuses for its
    escapes, pasted into the config the user was told to run. A name whose bytes are not
    UTF-8 cannot be in a TOML file at all: the line says so and what to do instead."""
    try:
        return f"port = {toml_basic_string(port)}"
    except NotTomlText:
        return (
            "# port: its name is not UTF-8, which a TOML file cannot hold: give it a UTF-8 "
            'name (a symlink, or a udev rule\'s SYMLINK) and write that here as port = "..."'
        )
