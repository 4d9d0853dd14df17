"""hadrian2/RTI_Dome (``ATMEGA_code.txt``): 32 LEDs on four TLC5940-style drivers.

From the sketch: 9600 baud; one character then ``Serial.parseInt()`` (1 s timeout): ``M<n>``
clears the registers, lights LED n, then pulses the camera line (100 ms wait, 100 ms pulse,
100 ms wait); ``A`` runs the whole sequence. No replies at all, no all-off: ``M`` with n ≥ 32
selects no driver, which leaves every LED off (and still pulses the camera). parseInt waits its
1 s timeout for more digits, so each command takes about 1.3 s. The board (ATmega32u4, native
USB) does not reset when the port opens.
"""

#: Four shift-register drivers of 8 outputs (``M<n>`` selects none past 31).
MAX_LED_COUNT = 32

#: An ATmega32u4 (the sketch drives ``LED_BUILTIN_TX``): ``Serial`` is its own USB, where
#: ``Serial.begin(9600)`` sets no rate, so any host baud rate reaches the sketch.
ANY_BAUDRATE = True

#: The Arduino "1200-baud touch" of an ATmega32u4 (the core's ``CDC.cpp``): a port whose line
#: rate is set to 1200 and whose DTR then drops (the host closing it) makes the board jump to
#: its bootloader (Caterina: about 8 s as another USB device, waiting for a new sketch). Any
#: rate reaches the sketch *except* this one, so a rig config asking for it is refused before
#: the port is opened: every close would reset the dome.
BOOTLOADER_TOUCH_BAUD = 1200

#: Can the link dim an LED? No: ``M<n>`` lights LED n; the serial command carries no
#: brightness (the drivers' grey-scale is set in the sketch, not by the host).
NO_DIMMING = "its only light command, M<n>, lights LED n (it carries no brightness)"

SPEC = {
    "name": "rti-dome-m",
    "led_count": MAX_LED_COUNT,
    "encoding": "text",
    "baudrate": 9600,
    "light": {"send": "M{index}", "delay_after_s": 1.5},
    "all_off": {"send": "M99", "delay_after_s": 1.5},
    "note": "hadrian2/RTI_Dome: M<n> lights LED n and pulses the camera; never answers",
}
