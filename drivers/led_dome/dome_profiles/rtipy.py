"""RTIPy / Ashmolean micro dome (BeebBenjamin/RTIPy, ``arduino/rti_py/rti_py.ino``).

From the sketch: 9600 baud; a command is whatever arrives before 1 s of silence
(``Serial.readString``). ``T,x,y,secs`` lights LoLShield LED (x = column 0..13, y = row 0..8),
**blocks** for ``secs`` whole seconds, then switches it off. The reply, printed before the LED
lights, is ``I received: <command> the instructionByte was: T`` with no line ending. There is no
"on until told off" command and no all-off: the LED goes dark by itself.
"""

#: The LoLShield's 14 × 9 matrix (``T,x,y``: x 0..13, y 0..8).
MAX_LED_COUNT = 126

#: Can the link dim an LED? No: ``T,x,y,secs`` lights LED (x, y) fully for whole seconds; the
#: command has no brightness field. Said in refusals.
NO_DIMMING = (
    "its only light command, T,x,y,secs, lights an LED fully for whole "
    "seconds (it carries no brightness)"
)

SPEC = {
    "name": "rtipy",
    "led_count": MAX_LED_COUNT,
    "encoding": "text",
    "columns": 14,
    "baudrate": 9600,
    "boot_wait_s": 2.0,
    "frame_silence_s": 1.0,
    "light_on_s": 2.0,
    "light": {
        "send": "T,{col},{row},{secs}",
        "reply": {
            "kind": "pattern",
            "pattern": r"I received: T,{col},{row},{secs} the instructionByte was: T",
        },
    },
    "note": "RTIPy sketch (Palaeopi / Ashmolean): timed LEDs, no all-off, never reads the host",
}
