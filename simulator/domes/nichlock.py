"""nichlock/rti (``arduino-program/src/main.cpp``) as its serial interface behaves.

Facts from the firmware (``main.cpp``'s ``setup`` and ``serialReact``, ``patterns.cpp``,
``displayCtrl.cpp``'s ``beginDisplay`` and ``calTouch``, ``headers.h``):

* **boot**: the baud rate comes from EEPROM (``DEFAULT_BAUD_RATE`` 115200 when none is stored
  yet), then ``beginDisplay`` prints ``Initialized Display.`` and the touch screen's calibrated
  bit; an uncalibrated screen **blocks the boot in its calibration** (two taps on the display,
  or ``c`` / ``s`` over serial) before the channel names and the ``For help, press 'h'`` prompt;
* **commands**: each received character is echoed with ``println``, the command runs, then a
  ``>`` prompt follows; ``0`` lights the next LED (``LED number: N; on pin P``, P = N % 8 + 1)
  and switches the previous one off; ``.`` steps back; ``x`` switches all off and rewinds;
  ``m`` prints free RAM; ``h`` its help; a newline gets ``!Please disable newlines!``; other
  keys ``Did nothing; that key is not assigned to a command.``. Past LED 191 ``0`` returns
  before the prompt;
* **menus**, which wait (forever) for their next key: ``a`` settings (baud rate, channel names,
  verbose output, display calibration), ``e`` EEPROM resets with a Y/N question, ``t`` the
  touch calibration, ``r`` / ``c`` a ring or column test that asks for two keys and then lights
  its LEDs; ``c`` at a menu's first question cancels it with no prompt after;
* **scans**: ``1``, ``2`` and ``3`` light each of that channel's 64 LEDs in turn (1 s on, 0.1 s
  off; channel 3 0.5 s and 0.2 s): about a minute during which the serial port is not read;
* ``s`` restarts the sketch (a software reset, no bootloader) unless ``c`` comes within 4 s;
* **verbose serial** (EEPROM byte 0, bit 7, toggled by ``a`` ``4``): ``setShutter``
  (``shutterCtrl.cpp``) prints ``Shutter turning on at: S seconds(Mms)`` for the LED ``0``
  lights, inside its reply (before the ``>``), and ``loop``'s ``checkShutters`` prints
  ``Shutter turning off at: 0 seconds(1ms)`` a moment after the prompt; ``beginShutters``
  prints ``\tStartig shutters...`` after the boot's prompt.

What a setting changes takes effect as on the board: a new baud rate at the next boot, a
cleared EEPROM (``er`` / ``ec``) at the next boot too (the boot then says the baud rate was
not found, and a de-calibrated screen holds it in calibration). The board's EEPROM outlives
its resets (the emulator object). Not emulated: the touch screen itself (nobody taps it, so a
calibration waits for its serial key), the display's patterns and profiles, the shutters.
"""

from __future__ import annotations

from collections.abc import Generator, Iterable
from dataclasses import dataclass, field

from rti_rig.simulator.domes.board import Board, Firmware, Read, Sleep

N_LEDS = 192
DEFAULT_BAUD_RATE = 115200
#: The settings menu's baud rates, by key (``a``, ``2``).
BAUD_CHOICES = {"1": 300, "2": 2400, "3": 9600, "4": 19200, "5": 115200}
#: ``CHANNEL_NAME_MAX_CHARACTERS``.
NAME_CHARS = 8
#: One AVR EEPROM byte write (``ec`` clears 4096 of them).
EEPROM_WRITE_S = 0.0033

HELP = (
    "RTI Serial Help List\nThese are commands that can be entered directly from the main "
    "command dialog.\nIf you are experiencing issues, make sure newline is disabled.\r\n"
    "\nCommand:\t\tFunction\r\n"
    "a\t\tEnter the settings dialog; contains settings beyond those on the display.\r\n"
    "0\t\tIncrementing up one LED at a time, turn on one LED.\r\n"
    ".\t\tIncrementing down one LED at a time, turn on one LED.\r\n"
    "x\t\tTurn off all LEDs and start the counting usedfor  above commands again at zero.\r\n"
    "1-3\t\tRun a column scan on the entered channel number.\r\n"
    "r\t\tLED test (rings).\r\n"
    "c\t\tLED test (columns).\r\n"
    "m\t\tView the bytes of RAM remaining on the device.\r\n"
    "s\t\tRestart the device. Cancelled with a c.\r\n"
    "er\t\tReset the following EEPROM variables:\n\t\t\tSerial is set to "
    f"{DEFAULT_BAUD_RATE} baud\n\t\t\tMatching of shutter outputs is disabled.\n\t\t\tDisplay "
    "is de-calibrated.\n\t\t\tDisplay diagnostics are turned off.\r\n"
    "ec\t\tClear ALL EEPROM - should only be done if absolutely necesary.\r\n"
)


@dataclass
class Eeprom:
    """What the sketch keeps in EEPROM (``headers.h``'s table), as far as serial shows it."""

    serial_set: bool = True  # byte 0, bit 0: a baud rate is stored
    baud: int = DEFAULT_BAUD_RATE
    touch_calibrated: bool = True  # byte 0, bit 2
    verbose: bool = False  # byte 0, bit 7
    #: As a builder sets them (``a``, ``3``: padded with spaces to 8 characters).
    names: list[str] = field(default_factory=lambda: ["UV      ", "White   ", "IR      "])
    default_channel: int = 1
    calibration: tuple[int, int, int, int] = (96, 930, 120, 905)


class _SoftReset(Exception):
    """``resetFunc()``: the sketch starts again at ``setup()`` (no bootloader)."""


class NichlockBoard(Board):
    name = "nichlock"
    led_count = N_LEDS
    baudrate = DEFAULT_BAUD_RATE
    boot_s = 1.0

    def __init__(
        self,
        baudrate: int = DEFAULT_BAUD_RATE,
        *,
        touch_calibrated: bool = True,
        verbose: bool = False,
        **kw: object,
    ) -> None:
        #: The board's EEPROM: ``baudrate`` is the rate stored there, ``touch_calibrated``
        #: whether its touch screen was calibrated (if not, every boot waits in calibration),
        #: ``verbose`` its verbose serial output (the settings menu's option 4).
        self.eeprom = Eeprom(baud=baudrate, touch_calibrated=touch_calibrated, verbose=verbose)
        #: ``millis()`` at which a shutter waits for ``checkShutters`` (None: none waits).
        self._shutter_due: int | None = None
        self.baudrate = baudrate
        super().__init__(**kw)  # type: ignore[arg-type]

    # ------------------------------------------------------------------ setup / loop

    def firmware(self) -> Firmware:
        while True:
            try:
                yield from self._setup()
                while True:
                    c = chr((yield Read()) or 0)
                    if self.begin_command():
                        yield from self._react(c)
                    yield from self._check_shutters()
            except _SoftReset:
                self.event("soft reset")

    def _name(self, channel: int) -> str:
        names = self.eeprom.names
        return names[channel] if 0 <= channel < len(names) else ""

    def _setup(self) -> Firmware:
        self._started = self.t  # millis() counts from here
        self.count = 0
        self.added_last = True
        rom = self.eeprom
        if not rom.serial_set:
            rom.baud, rom.serial_set = DEFAULT_BAUD_RATE, True
            self.baudrate = rom.baud
            self.println(
                "Serial initialized. Baud rate was NOT FOUND, and has been newly written into "
                "EEPROM"
            )
        else:
            self.baudrate = rom.baud
            self.println("Serial initialized from EEPROM")
        self.println(
            "Reflectance Transformation Imager Serial Interface v1.0\nDISABLE LINE ENDINGS"
        )
        yield Sleep(0.45)  # beginDisplay: three test colours, 150 ms each
        self.println("Initialized Display.")
        self.println("1" if rom.touch_calibrated else "0")
        if not rom.touch_calibrated:
            self.println("Touch screen was not calibrated. Starting Calibration..")
            yield from self._calibrate_touch()
        self.println("Setting channel color names:")
        for channel in range(3):
            self.println(self._name(channel))
        self.print("\nFor help, press 'h'\n>")
        self.set_lit(set())  # setPinModes: every port low
        if rom.verbose:
            self.println("\tStartig shutters...")  # beginShutters (the sketch's spelling)
        self._shutter_due = None

    def _millis(self) -> int:
        return int((self.t - self._started) * 1000)

    def _check_shutters(self) -> Firmware:
        """``loop``'s ``checkShutters``: the shutter the last ``0`` set on is switched on once
        its millis() passed (shutterOnTime 0: held while the LED is), said when verbose."""
        if self._shutter_due is None:
            return
        yield Sleep(0.002)  # millisDelay < millis(): the next millisecond, in loop()
        self._shutter_due = None
        if self.eeprom.verbose:
            self.println("Shutter turning off at: 0 seconds(1ms)")  # activationFromQ, del 0

    # ------------------------------------------------------------------ serialReact

    def _react(self, c: str) -> Firmware:
        self.println(c)
        if c == "0":
            if self.count >= N_LEDS:
                return  # before the prompt
            if not self.added_last:
                self.count += 2
            self.added_last = True
            self._step()
            self.count += 1
        elif c == ".":
            if self.count >= N_LEDS or self.count < 0:
                return
            if self.added_last:
                self.count -= 2
            self.added_last = False
            self._step()
            self.count -= 1
        elif c == "x":
            self.println("All LEDs shut off, active LED number reset to zero.")
            self.added_last = True
            self.set_lit(set())
            self.count = 0
        elif c == "m":
            self.println("RAM bytes remaining: 4021")
        elif c == "\n":
            self.println("!Please disable newlines!")
        elif c == "h":
            self.print(HELP)
        elif c == "a":
            if not (yield from self._settings()):
                return  # cancelled: no prompt
        elif c == "t":
            yield from self._calibrate_touch()
        elif c in ("1", "2", "3"):
            channel = int(c)
            self.println(f"Column scanning on channel {channel}: {self._name(channel - 1)}")
            on, off = (0.5, 0.2) if channel == 3 else (1.0, 0.1)
            yield from self._light_each(range((channel - 1) * 64, channel * 64), on, off)
        elif c in ("r", "c"):
            yield from self._ring_or_column(c)
        elif c == "s":
            yield from self._restart()
        elif c == "e":
            yield from self._eeprom_reset()
        else:
            self.println(
                "Did nothing; that key is not assigned to a command.\n\nEnter 'h' for help."
            )
        self.print(">")

    def _step(self) -> None:
        n = self.count
        self.println(f"LED number: {n}; on pin {n % 8 + 1}")
        self.set_lit({n} if 0 <= n < N_LEDS else set())
        # trigger(1, 1) -> setShutter(channel, 1, …, shutterOnWait 0): millisDelay = millis()
        due = self._millis()
        if self.eeprom.verbose:
            self.println(f"Shutter turning on at: {due // 1000} seconds({due}ms)")
        self._shutter_due = due

    def _key(self) -> Generator[Sleep | Read, int | None, str]:
        """``while (!Serial.available()) {}`` then ``Serial.read()``: waits however long."""
        return chr((yield Read()) or 0)

    def _choice(self, lines: Iterable[str]) -> Generator[Sleep | Read, int | None, str | None]:
        """A menu's lines printed and its key read; None for ``c``, which every menu of the
        sketch answers with "Cancelled" before returning to the LED commands."""
        for line in lines:
            self.println(line)
        pick = yield from self._key()
        if pick == "c":
            self.println("Cancelled")
            return None
        return pick

    # ------------------------------------------------------------------ menus

    def _settings(self) -> Generator[Sleep | Read, int | None, bool]:
        """The ``a`` menu; False when cancelled (``return`` before the prompt)."""
        rom = self.eeprom
        self.println(
            "Entered settings. Select one of the following options, or use 'c' to cancel. "
            "Settings requiring a restart are marked with '*'."
        )
        pick = yield from self._choice(
            (
                "1. Reset Specific Settings",
                "2. Serial Baud Rate*",
                "3. Change Channel/Color Names",
                "4. Verbose Serial",
                "5. Default Channel/Color",
            )
        )
        if pick is None:
            return False
        if pick == "1":
            self.println("SELECTED: Reset Specific Settings.")
            self.println("Enter the setting you would like to reset.")
            pick = yield from self._choice(
                (
                    "1. Serial Baud Rate*",
                    "2. Display Calibration*",
                    "3. ALL Channel/Color Names",
                    "*=Restart required.",
                )
            )
            if pick is None:
                return False
            if pick == "1":
                rom.baud = DEFAULT_BAUD_RATE
                self.println(f"Set serial baud rate to {rom.baud}. Restart to apply.")
            if pick == "2":
                rom.touch_calibrated = False  # toggled only if it was set
                self.println(
                    "New display calibration requested; restart to begin calibrating. \nStored "
                    "values have NOT been changed; if the calibration does not fix the issue "
                    "AND these values are identical to those written to serial after "
                    "calibrating, the EEPROM may be faulty (though other probelems are much "
                    "more likely.)"
                )
                self.println("Calibration values:")
                for label, value in zip(("x1", "x2", "y1", "y2"), rom.calibration, strict=True):
                    self.println(f"\t{label}: {value}")
            if pick == "3":
                self.println("Defaulting to the following channel color names:")
                rom.names = ["Ultra Vt", "White", "InfraRed"]
                for channel in range(3):
                    self.println(self._name(channel))
        elif pick == "2":
            self.println("SELECTED: Serial Baud Rate")
            self.println("Select the baud rate you would like to use:")
            pick = yield from self._choice(
                f"{key}. {rate}" + (" (Default)" if key == "5" else "")
                for key, rate in BAUD_CHOICES.items()
            )
            if pick is None:
                return False
            rate = BAUD_CHOICES.get(pick, rom.baud)  # another key stores the rate in use
            rom.baud = rate
            self.println(f"Set serial baud rate to {rate}. Restart to apply.")
        elif pick == "3":
            self.println("SELECTED: Change Channel/Color Names")
            self.println("Choose which Channel/Color name you would like to change: ")
            which = yield from self._choice(f"{c + 1}. {self._name(c)}" for c in range(3))
            if which is None:
                return False
            self.print("Enter the name you would like to change it to (press '\\' to finish): ")
            name = ""
            while True:
                ch = yield from self._key()
                self.print(ch)
                if ch == "\\":
                    self.println()
                    break
                name += ch
                if len(name) == NAME_CHARS:
                    self.println()
                    break
            if which in ("1", "2", "3"):
                rom.names[int(which) - 1] = name.ljust(NAME_CHARS)
        elif pick == "4":
            self.println("SELECTED: Verbose Serial")
            rom.verbose = not rom.verbose
            self.println(
                "Verbose serial output has been " + ("ENABLED" if rom.verbose else "DISABLED")
            )
        elif pick == "5":
            self.println("SELECTED: Default Channel/Color")
            self.println(
                "Enter the channel/color you would like as the default when using the display"
            )
            pick = yield from self._choice(f"{c + 1}. {self._name(c)}" for c in range(3))
            if pick is None:
                return False
            if pick in ("1", "2", "3"):
                rom.default_channel = int(pick)
        return True

    def _calibrate_touch(self) -> Firmware:
        """``calTouch``: waits for two taps nobody makes here; ``c`` cancels, ``s`` cancels and
        marks the screen calibrated (so later boots skip it); any other key is said back."""
        self.println(
            "Beginning display calibration. Follow the instructions on the display, or press "
            "'c' to cancel (press 's' to prevent further attempts to calibrate until "
            "calibration is reset in serial settings.)"
        )
        while True:
            key = yield from self._key()
            self.println(f"Recieved: {key}")
            if key == "c":
                self.println("Cancelled")
                return
            if key == "s":
                self.println("Cancelled; will not re-enter calibration until calibration is reset.")
                self.eeprom.touch_calibrated = True
                return

    def _light_each(self, leds: range, on_s: float, off_s: float, say: str = "") -> Firmware:
        """A pattern: each LED on for ``on_s`` then off for ``off_s`` (``say`` printed before
        each); the serial port is not read meanwhile (bytes wait in the 64-byte buffer)."""
        for i in leds:
            if say:
                self.print(say)
            self.set_lit({i})
            yield Sleep(on_s)
            self.set_lit(set())
            yield Sleep(off_s)

    def _ring_or_column(self, c: str) -> Firmware:
        """``r`` (which runs ``singleCol``) and ``c`` (``singleRing``): two keys, then the LEDs.

        The ``c to cancel`` they print is dead code in the sketch (after a ``break``): any key
        is taken as the number, and the pattern runs."""
        what = "Ring" if c == "r" else "Col"
        number_word = "ring" if c == "r" else "col"
        self.println(f"{what} scan called, enter {number_word} number... (c to cancel.)")
        number = yield from self._key()
        self.println("Enter channel... (c to cancel.)")
        channel_key = yield from self._key()
        channel = (ord(channel_key) - ord("0")) & 0xFF  # unsigned char arguments
        index = (ord(number) - ord("0")) & 0xFF
        self.println(f"Running column #{number}, on channel #{channel_key}: {self._name(channel)}")
        self.println(str(index))
        self.println(str(channel))
        first = (index - 1) & 0xFF
        if c == "r":  # singleCol: every 8th LED of the channel from the column on
            start = first if channel == 1 else 64 + first if channel == 2 else 128 + first
            end = 64 if channel == 1 else 128 if channel == 2 else 192
            leds = range(start, end, 8)
        else:  # singleRing: 8 LEDs in a row
            start = 8 * first + (channel - 1) * 64
            leds = range(start, start + 8)
        yield from self._light_each(leds, 0.1, 0.1, say=": y")

    def _restart(self) -> Firmware:
        self.println("Restarting... (c to cancel.)")
        end = self.t + 4.0
        while (left := end - self.t) > 0:
            key = yield Read(left)
            if key == ord("c"):
                self.println("Cancelled.\n")
                return
        self.println("Restarted.\n\n")
        self.println("~" * 38 + "\n\n")
        yield Sleep(0.1)
        raise _SoftReset

    def _eeprom_reset(self) -> Firmware:
        kind = yield from self._key()
        rom = self.eeprom
        if kind == "r":
            self.print("Resetting EEPROM variables, are you sure? (Y/N):")
            if (yield from self._key()) in ("Y", "y"):
                self.print(" Clearing. T- ")
                yield Sleep(2 * EEPROM_WRITE_S)
                # bytes 0 and 1: no baud rate stored, screen not calibrated, quiet output
                rom.serial_set = rom.touch_calibrated = rom.verbose = False
                self.println(" Done.")
            else:
                self.println(" Cancelled.")
        elif kind == "c":
            self.print("Clearing all EEPROM memory, are you sure? (Y/N): ")
            if (yield from self._key()) in ("Y", "y"):
                self.print(" Clearing. T- ")
                for digit in range(8, 0, -1):
                    self.print(str(digit))
                    yield Sleep(512 * EEPROM_WRITE_S)
                self.eeprom = Eeprom(
                    serial_set=False, baud=0, touch_calibrated=False, names=["", "", ""]
                )
                self.eeprom.calibration = (0, 0, 0, 0)
                self.println(" Done.")
            else:
                self.println(" Cancelled.")
