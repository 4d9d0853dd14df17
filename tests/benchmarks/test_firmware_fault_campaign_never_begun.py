"""A firmware-campaign session whose every run stops at connect is reported, not a traceback.

Such a session is run again from nothing up to the campaign's bound; it then read the manifest
its runs never wrote, and the campaign stopped with a traceback instead of its report.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest

import benchmarks.firmware_fault_campaign as ffc
from rti_rig.core.errors import DeviceError


def test_a_board_that_never_connects_is_counted_as_abandoned(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    runs: list[object] = []

    def stopped_at_connect(rig: object, *args: object, **kwargs: object) -> object:
        # the board fails its connect on every run, before the folder is begun
        runs.append(rig)
        raise DeviceError("dome on the emulated pty", "no reply (timeout)", "connect")

    monkeypatch.setattr(ffc, "run_session", stopped_at_connect)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    result = ffc.campaign(1, seed=1)
    s = result["stats"]
    assert len(runs) == 1 + ffc.MAX_RESUMES
    assert s["sessions"] == 1
    assert s.get("sessions_completed", 0) == 0
    assert s["abandoned"] == 1
    assert s["never_begun"] == 1
    text = ffc.report(result, 1, 1, 1.0)
    assert f"| sessions abandoned after {ffc.MAX_RESUMES} runs again (not completed) | 1 |" in text
    assert "| of which never begun (every run stopped at connect, nothing written) | 1 |" in text
    assert "| sessions completed | 0 |" in text
