"""``rti-rig probe`` reads what it knows of the Nab sketch from the sketch's profile.

The probe had its own copies of the sketch's rate, all-off, boot banner and replies: a fix to
the profile (``drivers/led_dome/dome_profiles/nab_rti_v1.py``) would not have reached the
probe, which would then identify, or switch off, a board by words the profile no longer held.
"""

from __future__ import annotations

import inspect
import re

from rti_rig.app.usecases import probe
from rti_rig.drivers.led_dome.dome_profiles import nab_rti_v1 as nab


def _words(pattern: str) -> str:
    """The literal text at the start of a profile's reply pattern (its regex escapes undone)."""
    literal = re.match(r"(?:\\.|[^\\.^$*+?{}\[\]|()])+", pattern)
    assert literal is not None, pattern
    return re.sub(r"\\(.)", r"\1", literal.group(0))


def test_the_probe_holds_no_copy_of_the_nab_profiles_words() -> None:
    source = inspect.getsource(probe)
    copies = [
        _words(nab.ALL_OFF["reply"]["pattern"]),
        _words(nab.ALL_ON_REPLY_PATTERN),
        _words(nab.SPEC["reset_pattern"]),
        _words(nab.SPEC["error_pattern"]),
        f'b"{nab.ALL_OFF["send"]}"',
        f"_NAB_BAUD = {nab.SPEC['baudrate']}",
        f'"{nab.SPEC["name"]}", _NAB_BAUD',
    ]
    held = [words for words in copies if words in source]
    assert not held, f"probe.py restates the Nab profile's {held}: read them from the profile"


def test_the_probe_answers_to_what_the_profile_says() -> None:
    """The sketch's replies, as its emulator prints them, are what the probe listens for."""
    from rti_rig.simulator.domes.nab_rti_v1 import BANNER

    assert probe._NAB_BANNER.search("\r\n".join(BANNER))
    assert probe._NAB_UNKNOWN_CODE.search("<INCORRECT FUNCTION CALL: 9>\r\n")
    assert probe._NAB_OFF_SAYS.search("<UV Turned off.>\r\n<All lights turned off.>\r\n")
    assert (nab.SPEC["name"], nab.SPEC["baudrate"]) == (probe._NAB_NAME, probe._NAB_BAUD)
