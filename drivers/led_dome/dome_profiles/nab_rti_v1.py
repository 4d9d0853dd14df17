"""The "RTI v1.0" Arduino sketch (Sjors H. Nab, 2024): 8×8 LEDs + UV, framed ``<code,arg>``.

From the sketch: 9600 baud; ``<0>`` all off, ``<3,N>`` LED N alone (row N / 8, column N % 8),
``<6>`` shutter (50 ms pulse, 500 ms wait, then the reply). Replies are ``<…>`` lines ending
CR LF; lighting one LED first switches all off, so ``<3,N>`` answers three lines. At boot (and
so at every port open: the board resets, ~1.6 s in the bootloader) it turns **all LEDs on** and
prints a banner, which is why the init sends an all-off straight away. An unknown code answers
``<INCORRECT FUNCTION CALL: n>``.
"""

ALL_OFF = {"send": "<0>", "reply": {"kind": "pattern", "pattern": r"<All lights turned off\.>"}}

#: What ``lightsOn()`` prints, in ``setup()`` (so at every boot, every LED lit) and after
#: ``<1>``, ``<4,ms>`` and ``<5,ms>``: heard, it means the board is lit (``rti-rig probe``).
ALL_ON_REPLY_PATTERN = r"<All lights turned on\.>"

#: The sketch drives an 8×8 matrix: ``<3,N>`` beyond LED 63 addresses no wired pin.
MAX_LED_COUNT = 64

#: Can the link dim an LED? No: the sketch's only light command, ``<3,N>``, switches LED N
#: fully on (no brightness field; ``<1>`` is all on, ``<2>`` the UV). Said in refusals.
NO_DIMMING = "its only light command, <3,N>, switches LED N fully on (it carries no brightness)"

SPEC = {
    "name": "nab-rti-v1",
    "led_count": MAX_LED_COUNT,
    "encoding": "text",
    "columns": 8,
    "baudrate": 9600,
    "boot_wait_s": 4.0,
    "ready_pattern": r"<6> Single photo\r?\n=+\r?\n",
    "init": [ALL_OFF],
    "light": {
        "send": "<3,{index}>",
        "reply": {
            "kind": "pattern",
            "pattern": r"<Single LED turned on, number: {index}, row: {row}, column: {col}>",
        },
    },
    "all_off": ALL_OFF,
    "shutter": {
        "send": "<6>",
        "reply": {"kind": "pattern", "pattern": r"<Shutter triggered\.>", "timeout_s": 1.5},
    },
    "reset_pattern": r"RTI-Dome intialized",
    "error_pattern": r"<INCORRECT FUNCTION CALL: -?\d+>",
    "boots_lit": True,
    "note": "RTI v1.0 sketch by Sjors H. Nab (2024); boots with every LED on",
}
