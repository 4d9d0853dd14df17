"""A session whose rig fails at every connect is given up, and counted as not finished.

The campaign runs a session that wrote nothing (no manifest) again into the same folder; with
a fault present at every connect that loop had no end, and the campaign never reported.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest

import benchmarks.fault_campaign as fc
from rti_rig.core.errors import DeviceError


class Spinning(BaseException):
    """Raised by the stand-in once the campaign has clearly stopped counting (not an
    Exception, so the campaign's traceback watcher does not swallow it)."""


def test_a_rig_that_never_connects_is_given_up_and_reported(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    connects: list[object] = []

    def never_connects(req: object, *args: object, **kwargs: object) -> object:
        # a rig that fails at connect, every time, before anything is written
        connects.append(req)
        if len(connects) > 100:
            raise Spinning(f"the same session was run {len(connects)} times from nothing")
        raise DeviceError("dome on /dev/ttyACM0", "no reply (timeout)", "connect")

    monkeypatch.setattr(fc, "open_new_session", never_connects)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    result = fc.campaign(1, seed=1, groups=("device",))
    s = result["stats"]
    assert len(connects) == 1 + fc.MAX_RUNS_FROM_NOTHING
    assert s["sessions"] == 1
    assert s["sessions_never_begun"] == 1
    assert s["sessions_not_finished"] == 1
    assert s.get("sessions_completed", 0) == 0
    assert s["sessions_restarted_from_nothing"] == fc.MAX_RUNS_FROM_NOTHING
    assert s["tracebacks"] == 0
    text = fc.report(result, 1, 1, 1.0, ("device",))
    assert (
        f"| sessions given up after {fc.MAX_RUNS_FROM_NOTHING} runs again that wrote nothing "
        "(a fault at every connect; counted as not finished) | 1 |"
    ) in text
    assert "| **sessions that could not be finished** | 1 |" in text
