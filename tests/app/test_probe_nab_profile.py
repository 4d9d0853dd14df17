"""``rti-rig probe`` reads what it knows of the Nab sketch from the sketch's profile.

The probe had its own copies of the sketch's rate, all-off, boot banner and replies: a fix to
the profile (``drivers/led_dome/dome_profiles/nab_rti_v1.py``) would not have reached the
probe, which would then identify, or switch off, a board by words the profile no longer held.
"""

from __future__ import annotations

import importlib.util
import sys
from types import ModuleType

import pytest

from rti_rig.app.usecases import probe
from rti_rig.drivers.led_dome.dome_profiles import nab_rti_v1 as nab


class _Board:
    """A Nab board that answers what it is sent with ``reply``: the bytes the probe wrote."""

    def __init__(self, reply: bytes, baudrate: int = 9600) -> None:
        self.baudrate = baudrate  # the port's rate, which the probe records with what it heard
        self.written = bytearray()
        self._reply = reply
        self._pending = b""

    def write(self, data: bytes) -> None:
        self.written += data
        self._pending = self._reply

    def read(self, timeout_s: float) -> bytes:
        out, self._pending = self._pending, b""
        return out


def _probe_loaded_now(monkeypatch: pytest.MonkeyPatch) -> ModuleType:
    """A fresh copy of the probe module, its constants read from the profile as it is now
    (the imported module read them once; reloading it would replace the classes other modules
    hold)."""
    spec = importlib.util.spec_from_file_location("_probe_copy", probe.__file__)
    assert spec is not None and spec.loader is not None
    copy = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, copy)  # its dataclasses look themselves up
    spec.loader.exec_module(copy)
    return copy


def test_a_change_to_the_profile_reaches_the_probe(monkeypatch: pytest.MonkeyPatch) -> None:
    """The probe switches a Nab board off, and names it, with what the profile says: a profile
    whose all-off, answer, rate or name changed is followed (a copy in the probe would not)."""
    changed = {"send": "<Z>", "reply": {"kind": "pattern", "pattern": r"<Dark now\.>"}}
    monkeypatch.setattr(nab, "ALL_OFF", changed)
    monkeypatch.setitem(nab.SPEC, "baudrate", 57600)
    monkeypatch.setitem(nab.SPEC, "name", "nab-renamed")
    copy = _probe_loaded_now(monkeypatch)
    board = _Board(b"<Dark now.>\r\n", baudrate=57600)
    result = copy.ProbeResult(port="loop://")
    copy._nab_off(result, board)
    assert bytes(board.written) == b"<Z>"
    assert "acknowledged" in result.lights and "NOT" not in result.lights, result.lights
    assert (copy._NAB_NAME, copy._NAB_BAUD) == ("nab-renamed", 57600)
    assert [h.baud for h in result.heard] == [57600]


def test_the_probe_answers_to_what_the_profile_says() -> None:
    """The sketch's replies, as its emulator prints them, are what the probe listens for."""
    from rti_rig.simulator.domes.nab_rti_v1 import BANNER

    assert probe._NAB_BANNER.search("\r\n".join(BANNER))
    assert probe._NAB_UNKNOWN_CODE.search("<INCORRECT FUNCTION CALL: 9>\r\n")
    assert probe._NAB_OFF_SAYS.search("<UV Turned off.>\r\n<All lights turned off.>\r\n")
    assert (nab.SPEC["name"], nab.SPEC["baudrate"]) == (probe._NAB_NAME, probe._NAB_BAUD)
