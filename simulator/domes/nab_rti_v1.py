"""The "RTI v1.0" sketch (Sjors H. Nab, 2024) as its source behaves, on an Arduino that resets.

Facts from the sketch: ``setup()`` calls ``lightsOn()`` (so **every LED lights at boot**) and
prints a banner; commands are framed ``<`` … ``>`` into a 32-byte buffer, split on commas and
read with ``atoi``; ``lightsOff()`` and ``lightsOn()`` first switch UV off (printing
``<UV Turned off.>``); ``singleLED`` switches all off first, then lights row N / 8, column N % 8;
the shutter holds its pin 50 ms, waits 500 ms, then answers; unknown codes answer
``<INCORRECT FUNCTION CALL: n>``. ``println`` ends lines with CR LF. The Uno-class board sits
~1.6 s in its bootloader after the port opens.
"""

from __future__ import annotations

from rti_rig.simulator.domes.board import Board, Firmware, Read, Sleep, atoi, c_div, c_mod

BANNER = [
    "===================",
    "RTI-Dome intialized",
    "Software Version: 1.0",
    "===================",
    "Commands:",
    "<0> All lights off",
    "<1> White LEDs on",
    "<2> UV LEDs on",
    "<3,$LED_NUMBER> single LED",
    "<4,$EXPOSURE_TIME> UVF photo - exposure time in MS",
    "<5,$EXPOSURE_TIME> RTI capture - exposure time in MS",
    "<6> Single photo",
    "===================",
]


class NabRtiV1Board(Board):
    name = "nab-rti-v1"
    led_count = 64
    baudrate = 9600
    boot_s = 1.6

    def firmware(self) -> Firmware:
        self.uv = False
        self._lights_on()
        for line in BANNER:
            self.println(line)
        buf = ""
        receiving = False
        while True:
            c = chr((yield Read()) or 0)
            if receiving:
                if c != ">":
                    buf = (buf + c)[:31]  # the sketch caps the index at numChars - 1
                    continue
                receiving = False
                if self.begin_command():
                    yield from self._call(buf)
                buf = ""
            elif c == "<":
                receiving, buf = True, ""

    def _call(self, data: str) -> Firmware:
        fields = data.split(",")
        code = atoi(fields[0]) if fields and fields[0] else 0
        arg = atoi(fields[1]) if len(fields) > 1 else 0
        if code == 0:
            self._lights_off()
        elif code == 1:
            self._lights_on()
        elif code == 2:
            self._lights_off()
            self.uv = True
            self.println("<UV Turned on.>")
        elif code == 3:
            self._lights_off()
            y, x = c_div(arg, 8), c_mod(arg, 8)
            self.set_lit({y * 8 + x} if 0 <= arg < 64 else set())  # outside: pins undefined
            self.println(f"<Single LED turned on, number: {arg}, row: {y}, column: {x}>")
        elif code == 6:
            yield from self._shutter()
        elif code in (4, 5):
            self.println("<not emulated>")  # UVF photo / firmware-run capture: not used by hosts
        else:
            self.println(f"<INCORRECT FUNCTION CALL: {code}>")

    def _shutter(self) -> Firmware:
        self.event("shutter")
        yield Sleep(0.05)
        yield Sleep(0.5)
        self.println("<Shutter triggered.>")

    def _lights_on(self) -> None:
        self.uv = False
        self.println("<UV Turned off.>")
        self.set_lit(set(range(64)))
        self.println("<All lights turned on.>")

    def _lights_off(self) -> None:
        self.uv = False
        self.println("<UV Turned off.>")
        self.set_lit(set())
        self.println("<All lights turned off.>")
