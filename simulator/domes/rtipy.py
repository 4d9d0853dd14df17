"""RTIPy's sketch (BeebBenjamin/RTIPy ``arduino/rti_py/rti_py.ino``) as its source behaves.

Facts from the sketch: a command is ``Serial.readString()``: everything until 1 s passes with
no byte; the reply ``I received: <command> the instructionByte was: <first field>`` is printed
with no line ending **before** acting; ``T,x,y,secs`` lights LoLShield LED (x, y) (14 columns ×
9 rows), ``delay``s ``secs`` whole seconds (blocking: bytes received meanwhile wait in the
64-byte buffer), then switches it off; ``L`` lights LED (3, 0) for 60 s. The ``C`` capture
loop is not emulated (it fires a Nikon IR remote; hosts driving single LEDs do not use it).
"""

from __future__ import annotations

from rti_rig.simulator.domes.board import Board, Firmware, Read, Sleep, atoi

COLUMNS, ROWS = 14, 9


def get_value(data: str, sep: str, index: int) -> str:
    parts = data.split(sep)
    return parts[index] if index < len(parts) else ""


class RtiPyBoard(Board):
    name = "rtipy"
    led_count = COLUMNS * ROWS
    baudrate = 9600
    boot_s = 1.6
    self_timed = True  # ``T,x,y,secs``: the LED goes dark after secs, whatever the host does

    def firmware(self) -> Firmware:
        while True:
            first = yield Read()
            text = chr(first or 0)
            while True:  # readString: until 1 s of silence
                b = yield Read(1.0)
                if b is None:
                    break
                text += chr(b)
            if not self.begin_command():
                continue
            instruction = get_value(text, ",", 0)
            self.print(f"I received: {text} the instructionByte was: {instruction}")
            if instruction == "L":
                self.print("I should be lighting an LED right now!")
                yield from self._timed(3, 0, 60)
            elif instruction == "T":
                x = atoi(get_value(text, ",", 1))
                y = atoi(get_value(text, ",", 2))
                yield from self._timed(x, y, atoi(get_value(text, ",", 3)))

    def _timed(self, x: int, y: int, secs: int) -> Firmware:
        on = 0 <= x < COLUMNS and 0 <= y < ROWS
        if on:
            self.set_lit({y * COLUMNS + x})
        yield Sleep(max(0, secs))
        self.set_lit(set())
