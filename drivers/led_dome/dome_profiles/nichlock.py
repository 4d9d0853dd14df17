"""nichlock/rti (``arduino-program/src/main.cpp``): 192 LEDs on three channels, stepping only.

From the firmware: one character a command, no line endings (a ``\\n`` gets
``!Please disable newlines!``); each command is echoed (char + CR LF) and ends with a ``>``
prompt. ``0`` lights the next LED and prints ``LED number: N; on pin P``; ``x`` switches all off
and rewinds to LED 0 (``All LEDs shut off, active LED number reset to zero.``). There is no
addressing, so the driver steps and checks the number the firmware prints (a missed or double
step is a named error). With verbose serial on (the settings menu's option 4, in EEPROM) each
step's reply also says ``Shutter turning on at: S seconds(Mms)`` before the prompt, and
``Shutter turning off at: …`` follows it a moment later (read past as stale text). Baud rate
from EEPROM, 115200 on a fresh board: ``headers.h`` sets
``DEFAULT_BAUD_RATE 115200`` and its settings menu lists "115200 (Default)"; the comment in
``setup()`` that says 9600 is stale. A board whose EEPROM was set otherwise needs ``baudrate``
in the rig config. Arduino Mega: resets when the port opens and prints a banner ending with
``For help, press 'h'`` and the prompt, unless its touch screen is uncalibrated: then the boot
waits in the calibration, which answers each key ``Recieved: <key>`` (the firmware's spelling);
that is said as such, with what to do.
"""

#: The Arduino Mega sketch steps through 192 LEDs.
MAX_LED_COUNT = 192

#: Can the link dim an LED? No: ``0`` steps to the next LED and lights it; nothing sets a
#: brightness.
NO_DIMMING = "it only steps to the next LED (key 0) and lights it; no command carries a brightness"

SPEC = {
    "name": "nichlock",
    "led_count": MAX_LED_COUNT,
    "encoding": "text",
    "baudrate": 115200,
    "boot_wait_s": 4.0,
    "ready_pattern": r"For help, press 'h'\r?\n>",
    "stepping": True,
    "light": {
        "send": "0",
        # verbose serial (the settings menu's option 4) puts "Shutter turning on at: S
        # seconds(Mms)" between the LED line and the prompt (shutterCtrl.cpp's setShutter)
        "reply": {
            "kind": "pattern",
            "pattern": (
                r"LED number: {index}; on pin \d+\r\n"
                r"(?:Shutter turning on at: [^\r\n>]*\r\n)?>"
            ),
        },
    },
    "all_off": {
        "send": "x",
        "reply": {
            "kind": "pattern",
            "pattern": r"All LEDs shut off, active LED number reset to zero\.\r\n>",
        },
    },
    "reset_pattern": r"Reflectance Transformation Imager Serial Interface",
    "error_pattern": r"Did nothing; that key is not assigned",
    # calTouch (displayCtrl.cpp) answers every key but c and s so, and nothing else does: the
    # board boots into it while its touch screen is uncalibrated, and the display's settings
    # page starts it too. rti-rig does not send 'c' itself: at the prompt that key starts the
    # firmware's column test, which waits for two keys and then lights LEDs.
    "waiting_pattern": r"Recieved: [^\r\n]*\r\n",
    "waiting_advice": (
        "the dome is in its touch-screen calibration (an uncalibrated screen holds every boot "
        "there); tap the two red circles on its display, or press 'c' in a serial terminal "
        "(115200 baud unless changed) to skip it this once, or 's' to stop it for good; then "
        "run again"
    ),
    "note": "nichlock/rti Arduino Mega shield: step next/all-off, position verified",
}
