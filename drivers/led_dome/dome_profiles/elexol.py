"""Elexol USB I/O 24R1 board as used by jcupitt/rtiacquire (``lights.py``, ``ledmap.py``).

From the host code: 38400 baud; ``?`` answers ``USB I/O 24R1`` CR LF; ``!A\\0``, ``!B\\0``,
``!C\\0`` make the three ports outputs; ``A<byte>B<byte>C<byte>`` sets the 24 outputs; no
acknowledgements. Which outputs light which LED comes from an LED map file (``led-maps.txt``:
``** name **`` sections of byte triples); without one, LED i is output bit i % 8 of port i // 8.
"""

DEFAULT_MAP = [[(1 << (i % 8)) if i // 8 == port else 0 for port in range(3)] for i in range(24)]

#: Can the link dim an LED? No: the board's outputs are relays/IO lines, each on or off.
NO_DIMMING = (
    "its port commands (A/B/C + one byte) switch each output on or off "
    "(one bit each, no brightness)"
)

SPEC = {
    "name": "elexol-24r1",
    "led_count": 24,
    "encoding": "bytes",
    "baudrate": 38400,
    "boot_wait_s": 0.2,
    "handshake": {"send": "3F", "reply": {"kind": "pattern", "pattern": r"USB I/O 24R1\r\n"}},
    "init": [{"send": "21 41 00 21 42 00 21 43 00"}],
    # The board never answers, so a power blip that turned its ports back into inputs would go
    # unseen: every light and all-off sets the directions again first (9 bytes, 2.3 ms).
    "light": {"send": "21 41 00 21 42 00 21 43 00 41 {map0} 42 {map1} 43 {map2}"},
    "all_off": {"send": "21 41 00 21 42 00 21 43 00 41 00 42 00 43 00"},
    "led_map": DEFAULT_MAP,
    "note": "Elexol USB I/O 24R1 relay/IO board (rtiacquire): LED map file, no acknowledgements",
}
