"""``rti-rig probe PORT``: which known dome firmware answers on a serial port.

Least intrusive first: listen to what the board prints when the port opens (the Nab sketch and
nichlock's firmware print banners), then ask questions that light nothing (the Elexol board's
``?``), then commands that switch everything off (minirti's all-zero mask), and last RTIPy's
``T,0,0,0`` (LED 0 for zero seconds). A firmware identified with its LEDs possibly on (the Nab
sketch boots fully lit) is sent its all-off before the probe returns. A dome that never answers
(hadrian2/RTI_Dome) cannot be identified; the result says so, with what was heard.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from rti_rig.drivers.led_dome.transport import SerialTransport, TransportError


@dataclass(frozen=True)
class ProbeRequest:
    port: str
    #: Seconds to listen after opening (covers an Arduino's bootloader and banner).
    listen_s: float = 2.6


@dataclass
class ProbeResult:
    port: str
    profile: str | None = None
    #: The baud rate the firmware answered at (with ``profile``).
    baudrate: int | None = None
    #: What each probe heard (probe description → text), in the order tried.
    heard: list[tuple[str, str]] = field(default_factory=list)
    lights: str = "nothing was lit by the probe"
    error: str | None = None
    #: What else the firmware showed that the user must act on before a check (or None).
    note: str | None = None

    def config_lines(self) -> list[str]:
        if self.profile is None:
            return []
        # the rate it answered at is said too: a config copied from the example (or the
        # guide) keeps its "baudrate = 115200", which overrides the profile's own rate, and
        # a 9600-baud firmware then failed its check with no word of the rate that works
        rate = [f"baudrate = {self.baudrate}"] if self.baudrate is not None else []
        return ["[dome.serial]", f'port = "{self.port}"', f'profile = "{self.profile}"', *rate]

    def lines(self) -> list[str]:
        out = []
        for what, text in self.heard:
            shown = text.strip().replace("\r", "")[-200:] or "(nothing)"
            out.append(f"{what}: {shown!r}")
        if self.error:
            out.append(f"ERROR: {self.error}")
        if self.error and not self.heard:
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
        else:
            out.append(f"Found: {self.profile}. Rig-config lines to use:")
            out += ["  " + line for line in self.config_lines()]
        out.append(f"Lights: {self.lights}")
        if self.note:
            out.append(f"Note: {self.note}")
        return out


def _exchange(port: str, baud: int, wait_s: float, send: bytes, listen_s: float) -> str:
    """Open at ``baud``, wait ``wait_s`` (collecting the banner), send, listen; all text heard.

    A probe met by silence is sent once more on the same open port (every probe is harmless
    to the firmwares known, and none resets a board when it is repeated): one reply lost on
    the line, an Elexol board's ``USB I/O 24R1`` to ``?``, had made the probe say that no
    known firmware answered, where a session's driver resends the same command."""
    t = SerialTransport(port, baud)
    t.open()
    try:
        heard = bytearray()
        heard += _listen(t, wait_s)
        if send:
            t.write(send)
            answer = _listen(t, listen_s)
            if not answer:
                t.write(send)
                answer = _listen(t, listen_s)
            heard += answer
        return heard.decode("latin-1")
    finally:
        t.close()


def _listen(t: SerialTransport, seconds: float) -> bytes:
    out = bytearray()
    end = time.monotonic() + seconds
    while (left := end - time.monotonic()) > 0:
        out += t.read(min(left, 0.1))
    return bytes(out)


def _nab_found(result: ProbeResult, wait: float) -> ProbeResult:
    """The Nab sketch answered: it boots with every LED on, so switch them off before leaving."""
    result.profile, result.baudrate = "nab-rti-v1", 9600
    t = SerialTransport(result.port, 9600)
    t.open()
    off = ""
    try:
        _listen(t, wait)  # the board resets as the port opens: its bootloader, then its banner
        # sent again on the same open port if unanswered (reopening it would reset the board,
        # which lights every LED again): one lost reply, or a <0> the board missed, had ended
        # the probe with "NOT acknowledged: check the dome", where a session resends it
        for what, listen_s in (("all off <0>", 0.6), ("all off <0> again", 1.2)):
            t.write(b"<0>")
            off = _listen(t, listen_s).decode("latin-1")
            result.heard.append((what, off))
            if "<All lights turned off.>" in off:
                break
    finally:
        t.close()
    result.lights = (
        "the sketch boots with every LED on; all-off sent and acknowledged"
        if "<All lights turned off.>" in off
        else "the sketch boots with every LED on; all-off sent twice but NOT acknowledged: check "
        "the dome"
    )
    return result


#: What nichlock/rti's firmware prints, at whatever rate its EEPROM holds: its banner, the free
#: RAM (``m``) and its answer to a key it does not know (``arduino-program/src/main.cpp``).
_NICHLOCK_SAYS = (
    "Reflectance Transformation Imager Serial Interface",
    "RAM bytes remaining",
    "Did nothing; that key is not assigned",
)


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
    result.lights = "the firmware boots with every LED off; nothing that lights was sent"
    if "Starting Calibration" in text and "For help, press 'h'" not in text:
        # beginDisplay holds the boot in calTouch while the touch screen is uncalibrated: a
        # check then meets the calibration, not the prompt (it says so too)
        result.note = (
            "its boot waits in its touch-screen calibration (the screen is not calibrated): "
            "tap the two red circles on its display, or press 'c' in a serial terminal to skip "
            "it this once ('s' to stop it for good), before rti-rig check"
        )
    return True


def probe(request: ProbeRequest) -> ProbeResult:
    """Try the known firmwares on ``request.port``; see the module docstring for the order."""
    result = ProbeResult(request.port)
    port, wait = request.port, request.listen_s
    try:
        text = _exchange(port, 9600, wait, b"", 0)
        result.heard.append(("listen at 9600 baud", text))
        if "RTI-Dome intialized" in text or "<All lights turned on.>" in text:
            return _nab_found(result, wait)
        if _nichlock_found(result, text, 9600):
            return result
        text = _exchange(port, 115200, wait, b"", 0)
        result.heard.append(("listen at 115200 baud", text))
        if _nichlock_found(result, text, 115200):
            return result
        # nichlock's settings menu (``a``, ``2``) stores 19200 or 2400 too, taken at its next
        # boot: listened for before anything is sent, since bytes at another rate reach such a
        # board as keys of its menus (a board set so had been "No known dome firmware")
        for rate in NICHLOCK_OTHER_RATES:
            text = _exchange(port, rate, wait, b"", 0)
            result.heard.append((f"listen at {rate} baud", text))
            if _nichlock_found(result, text, rate):
                return result
        text = _exchange(port, 38400, 0.2, b"?", 0.5)
        result.heard.append(("'?' at 38400 baud", text))
        if "USB I/O 24R1" in text:
            result.profile, result.baudrate = "elexol-24r1", 38400
            return result
        text = _exchange(port, 115200, wait, b"m", 0.5)
        result.heard.append(("'m' (free RAM) at 115200 baud", text))
        if _nichlock_found(result, text, 115200):
            return result
        text = _exchange(port, 9600, wait, b"<9>", 0.6)
        result.heard.append(("'<9>' (an unknown code) at 9600 baud", text))
        if "<INCORRECT FUNCTION CALL: 9>" in text or "RTI-Dome intialized" in text:
            return _nab_found(result, wait)
        if _nichlock_found(result, text, 9600):
            return result
        text = _exchange(port, 9600, 1.6, b"\x42" + bytes(8), 0.5)
        result.heard.append(("0x42 + empty mask at 9600 baud", text))
        if _nichlock_found(result, text, 9600):
            return result
        if text.endswith("\x01"):
            result.profile, result.baudrate = "minirti", 9600
            result.lights = "the probe sent an all-off mask, acknowledged"
            return result
        text = _exchange(port, 9600, wait, b"T,0,0,0", 1.8)
        result.heard.append(("'T,0,0,0' at 9600 baud", text))
        if "I received: T,0,0,0 the instructionByte was: T" in text:
            result.profile, result.baudrate = "rtipy", 9600
            result.lights = "LED (0, 0) was asked for zero seconds: it stays dark"
            return result
        # a board that resets at every opening and is still in its bootloader when each
        # listen ends is heard by no probe; the Nab sketch then lights every LED as it boots,
        # after the probe had said only that nothing lighting was sent
        result.lights = (
            f"nothing that lights an LED was sent; but a board that resets when its port opens "
            f"(an Arduino) and takes longer than the {wait:g} s each probe listens to boot "
            "answers none of them, and lights whatever its firmware lights at boot once the "
            "probe has closed the port (the Nab sketch: every LED): look at the dome"
        )
    except TransportError as exc:
        result.error = str(exc)
        if result.profile == "nab-rti-v1":
            # it answered, so it booted, and it boots with every LED on
            result.lights = (
                "the sketch boots with every LED on and the all-off could NOT be sent: the dome "
                "may be fully lit; switch it off at its power supply"
            )
        elif result.heard:
            sent = ", ".join(what for what, _ in result.heard)
            result.lights = (
                f"the port failed after these probes ({sent}); none of them lights an LED on "
                "the firmwares known, but the dome's state is not known"
            )
        else:
            result.lights = "the port could not be used; nothing was sent"
    return result
