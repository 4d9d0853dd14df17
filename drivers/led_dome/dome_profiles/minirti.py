"""The minirti dome (michaelwh/rticap ``domecontroller.py``; the firmware is not published).

From the host code: 9600 baud; byte ``0x42`` then 8 bytes, a bitmask of the 64 LEDs (LED i is
bit ``7 - i % 8`` of byte ``i // 8``: the host builds each byte's bit string from LED 0 on the
left); the dome acknowledges with the byte ``0x01``. The host waits 1.5 s after opening, because
bytes sent earlier get lost. All off = an all-zero mask.
"""

#: The 8-byte bitmask carries 64 LEDs.
MAX_LED_COUNT = 64

#: Can the link dim an LED? No: the one command is an on/off bitmask of the 64 LEDs.
NO_DIMMING = (
    "its only command, 0x42 + an 8-byte bitmask, switches each LED on or "
    "off (one bit each, no brightness)"
)

SPEC = {
    "name": "minirti",
    "led_count": MAX_LED_COUNT,
    "encoding": "bytes",
    "mask_bit_order": "msb-first",
    "mask_bytes": 8,
    "baudrate": 9600,
    "boot_wait_s": 1.5,
    "light": {"send": "42 {mask}", "reply": {"kind": "byte", "byte": 1}},
    "all_off": {"send": "42 {mask}", "reply": {"kind": "byte", "byte": 1}},
    "note": "minirti dome (rticap, Southampton 2011): 0x42 + 64-bit mask, ack 0x01",
}
