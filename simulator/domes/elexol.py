"""The Elexol USB I/O 24R1 board as jcupitt/rtiacquire drives it (``lights.py``).

Facts from the host code: 38400 baud; ``?`` answers ``USB I/O 24R1`` CR LF; ``!`` + port letter
+ byte sets the port's direction (0 = all outputs); a port letter + byte sets its outputs; no
acknowledgements. An FTDI board: opening the port does not reset it. Assumed from the board's
kind: ports power up as inputs (LEDs dark) with their output latches at 0. Which LEDs an output
pattern lights comes from the LED map (LED i lit when all its map bits are driven).
"""

from __future__ import annotations

from rti_rig.simulator.domes.board import Board, Firmware, Read

PORTS = b"ABC"


class ElexolBoard(Board):
    name = "elexol-24r1"
    baudrate = 38400
    boot_s = 0.0
    resets_on_open = False

    def __init__(self, led_map: tuple[tuple[int, ...], ...], **kw: object) -> None:
        self.led_map = led_map
        self.led_count = len(led_map)
        super().__init__(**kw)  # type: ignore[arg-type]

    def firmware(self) -> Firmware:
        self.direction = [0xFF, 0xFF, 0xFF]
        self.latch = [0, 0, 0]
        while True:
            c = yield Read()
            if c == ord("?"):
                if self.begin_command():
                    self.print("USB I/O 24R1\r\n")
            elif c == ord("!"):
                port, value = (yield Read()), (yield Read())
                if port in PORTS and value is not None:
                    self.direction[PORTS.index(port)] = value
            elif c in PORTS:
                value = yield Read()
                if value is not None and self.begin_command():
                    self.latch[PORTS.index(c)] = value
            self._update()

    def _update(self) -> None:
        driven = [self.latch[p] & ~self.direction[p] & 0xFF for p in range(3)]
        lit = set()
        for i, row in enumerate(self.led_map):
            bits = list(row[:3]) + [0] * (3 - len(row[:3]))
            if any(bits) and all(driven[p] & bits[p] == bits[p] for p in range(3)):
                lit.add(i)
        self.set_lit(lit)
