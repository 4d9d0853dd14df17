"""The minirti dome (michaelwh/rticap) as its host code shows it; its firmware is unpublished.

Facts from ``domecontroller.py``: 9600 baud; ``0x42`` then 8 bytes, a bitmask of the 64 LEDs
(LED i = bit 7 - i % 8 of byte i // 8); the dome answers the byte ``0x01``; bytes sent within
1.5 s of opening get lost. Assumed (not published, documented in docs/domes.md): the board
resets on open (~1.4 s), boots dark, ignores bytes other than ``0x42`` between commands, and
gives up a half-received mask after 1 s.
"""

from __future__ import annotations

from rti_rig.simulator.domes.board import Board, Firmware, Read


class MiniRtiBoard(Board):
    name = "minirti"
    led_count = 64
    baudrate = 9600
    boot_s = 1.4

    def firmware(self) -> Firmware:
        while True:
            if (yield Read()) != 0x42:
                continue
            mask = bytearray()
            while len(mask) < 8:
                b = yield Read(1.0)
                if b is None:
                    break
                mask.append(b)
            if len(mask) < 8 or not self.begin_command():
                continue
            self.set_lit({i for i in range(64) if mask[i // 8] >> (7 - i % 8) & 1})
            self.print(b"\x01")
