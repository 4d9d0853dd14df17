"""hadrian2/RTI_Dome (``ATMEGA_code.txt``) as its source behaves.

Facts from the sketch: ``Serial.read()`` one character, then ``Serial.parseInt()`` (skips
non-digits, reads digits, stops at a non-digit it leaves in the buffer or after its 1 s
timeout, 0 if no digit came); ``M`` clears the shift registers (all off), shifts in LED n's bit
on driver n / 8 (none when n / 8 is not 0..3), latches it, then waits 100 ms, pulses the camera
line 100 ms, waits 100 ms; ``A`` runs the whole 32-LED sequence (not emulated). No replies. The
board is an ATmega32u4 (the sketch drives ``LED_BUILTIN_TX``, which only the 32u4 boards
define, and uses pins 0 and 1, the UART's, as outputs while ``Serial`` still works): its
``Serial`` is native USB, so opening the port does not reset it and the host's baud rate is
not used (``Serial.begin(9600)`` sets nothing on a USB CDC port): any rate reaches the sketch,
except 1200: the Arduino core's USB code jumps to the bootloader when a port set to 1200 baud
drops DTR (the "1200-baud touch" an uploader uses), so a host that opens the port at 1200 and
closes it leaves the sketch stopped for the bootloader's 8 s, then restarted from ``setup()``.
"""

from __future__ import annotations

from rti_rig.simulator.domes.board import Board, Firmware, Read, Sleep, c_div, c_mod


class RtiDomeBoard(Board):
    name = "rti-dome-m"
    led_count = 32
    baudrate = 9600
    boot_s = 0.0
    resets_on_open = False
    native_usb = True
    bootloader_touch_baud = 1200  # the 32u4 core's CDC code: 1200 baud, then DTR low

    def firmware(self) -> Firmware:
        while True:
            data = yield Read()
            num = yield from self._parse_int()
            if data == ord("M") and self.begin_command():
                self.set_lit(set())  # clearReg
                driver = c_div(num, 8)
                self.set_lit({driver * 8 + c_mod(num, 8)} if 0 <= driver < 4 else set())
                yield Sleep(0.1)
                self.event("camera pulse")
                yield Sleep(0.1)
                yield Sleep(0.1)

    def _parse_int(self) -> Firmware:
        while True:  # skip anything that cannot start a number
            b = yield Read(1.0, peek=True)
            if b is None:
                return 0
            if chr(b).isdigit() or b == ord("-"):
                break
            yield Read()
        sign, value = 1, 0
        while True:
            b = yield Read(1.0, peek=True)
            if b is None:
                break
            if b == ord("-") and value == 0:
                sign = -1
            elif not chr(b).isdigit():
                break
            else:
                value = value * 10 + b - 48
            yield Read()
        return sign * value
