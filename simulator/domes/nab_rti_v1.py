"""The "RTI v1.0" sketch (Sjors H. Nab, 2024) as its source behaves, on an Arduino that resets.

Facts from the sketch: ``setup()`` calls ``lightsOn()`` (so **every LED lights at boot**) and
prints a banner; commands are framed ``<`` … ``>`` into a 32-byte buffer, split with ``strtok``
on commas (which skips empty fields: ``<3,,7>`` is ``<3,7>``) and read with ``atoi``;
``lightsOff()`` and ``lightsOn()`` first switch UV off (printing ``<UV Turned off.>``);
``singleLED`` switches all off first, then lights row N / 8, column N % 8; the shutter holds its
pin 50 ms, waits 500 ms, then answers; unknown codes answer ``<INCORRECT FUNCTION CALL: n>``.
``<4,ms>`` (``uvPhoto``) shoots one frame under the UV LEDs and ``<5,ms>`` (``rti``) runs the
sketch's own 64-LED capture, one shutter per LED; both block for their whole run and end with
``lightsOn()``: **every LED lit** again. ``println`` ends lines with CR LF. The Uno-class board
sits ~1.6 s in its bootloader after the port opens.
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
        fields = [f for f in data.split(",") if f]  # strtok: empty fields are skipped
        code = atoi(fields[0]) if fields else 0
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
        elif code == 4:
            yield from self._uv_photo(arg)
        elif code == 5:
            yield from self._rti(arg)
        elif code == 6:
            yield from self._shutter()
        else:
            self.println(f"<INCORRECT FUNCTION CALL: {code}>")

    def _shutter(self) -> Firmware:
        self.event("shutter")
        yield Sleep(0.05)
        yield Sleep(0.5)
        self.println("<Shutter triggered.>")

    def _uv_photo(self, exposure_ms: int) -> Firmware:
        """``uvPhoto``: one frame under the UV LEDs, then every white LED lit again."""
        self.println("===================")
        self.println("<Initialising UVF photograph>")
        self._lights_off()
        self._lights_off()  # uvOn() switches all off once more before the UV pin
        self.uv = True
        self.println("<UV Turned on.>")
        yield from self._shutter()
        yield Sleep(_delay_s(exposure_ms))
        self.uv = False
        self.println("<UV Turned off.>")
        self._lights_on()
        self.println("<UVF Photograph taken>")
        self.println("===================")

    def _rti(self, exposure_ms: int) -> Firmware:
        """``rti``: the sketch's own capture, row by row, a shutter and ``exposure_ms`` per LED."""
        expected = c_div(exposure_ms, 1000) * 63 + 500 * 63 // 1000  # the sketch's int arithmetic
        self._lights_off()
        self.println("===================")
        self.println("<RTI Capture Initialised>")
        minutes, seconds = c_div(expected, 60), c_mod(expected, 60)
        self.println(f"<Time to completion: {minutes} minutes and {seconds} seconds>")
        for y in range(8):
            self.println(f"<Completion: {100 // 8 * y}%>")
            for x in range(8):
                self.set_lit({y * 8 + x})
                yield from self._shutter()
                yield Sleep(_delay_s(exposure_ms))
                self.set_lit(set())
        self._lights_on()
        self.println("<RTI Capture Completed>")
        self.println("===================")

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


def _delay_s(ms: int) -> float:
    """``delay(ms)`` of an ``int``: a negative one becomes a huge ``unsigned long``, as in C."""
    return (ms % 2**32) / 1000.0
