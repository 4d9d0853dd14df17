"""nichlock/rti (``arduino-program/src/main.cpp``) as its serial interface behaves.

Facts from the firmware: each received character is echoed with ``println``, the command runs,
then a ``>`` prompt follows; ``0`` lights the next LED (``LED number: N; on pin P``, P = N % 8 +
1) and switches the previous one off; ``.`` steps back; ``x`` switches all off and rewinds
(``All LEDs shut off, active LED number reset to zero.``); ``m`` prints free RAM; a newline gets
``!Please disable newlines!``; other keys ``Did nothing; that key is not assigned to a
command.``. Past LED 191 ``0`` returns before the prompt. The Arduino Mega resets when the port
opens; the banner ends with ``For help, press 'h'`` and the prompt. Scans, menus and the touch
screen are not emulated. The baud rate is the one stored in EEPROM (``setup()`` reads it;
the ``a`` settings menu offers 300, 2400, 9600, 19200 and 115200, ``DEFAULT_BAUD_RATE`` in
``headers.h`` is 115200): ``baudrate`` gives a board set otherwise.
"""

from __future__ import annotations

from rti_rig.simulator.domes.board import Board, Firmware, Read

N_LEDS = 192


class NichlockBoard(Board):
    name = "nichlock"
    led_count = N_LEDS
    baudrate = 115200
    boot_s = 1.0

    def __init__(self, baudrate: int = 115200, **kw: object) -> None:
        self.baudrate = baudrate  # the rate stored in the board's EEPROM
        super().__init__(**kw)  # type: ignore[arg-type]

    def firmware(self) -> Firmware:
        self.count = 0
        self.added_last = True
        self.println("Serial initialized from EEPROM")
        self.println(
            "Reflectance Transformation Imager Serial Interface v1.0\nDISABLE LINE ENDINGS"
        )
        self.println("Setting channel color names:")
        for name in ("UV       ", "White    ", "IR       "):
            self.println(name)
        self.print("\nFor help, press 'h'\n>")
        while True:
            c = chr((yield Read()) or 0)
            if not self.begin_command():
                continue
            self.println(c)
            if c == "0":
                if self.count >= N_LEDS:
                    continue
                if not self.added_last:
                    self.count += 2
                self.added_last = True
                self._step("next")
                self.count += 1
            elif c == ".":
                if self.count >= N_LEDS or self.count < 0:
                    continue
                if self.added_last:
                    self.count -= 2
                self.added_last = False
                self._step("previous")
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
            else:
                self.println(
                    "Did nothing; that key is not assigned to a command.\n\nEnter 'h' for help."
                )
            self.print(">")

    def _step(self, _direction: str) -> None:
        n = self.count
        self.println(f"LED number: {n}; on pin {n % 8 + 1}")
        self.set_lit({n} if 0 <= n < N_LEDS else set())
