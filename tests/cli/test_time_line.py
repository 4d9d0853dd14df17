"""The "Session time on the real rig" line counts the exposure metering run before the session.

``--auto-exposure`` takes its test shots before the first image (7 on the emulated card dome,
8.4 s on its rig): the line had left them out. The manifest's exposure evidence records their
time on the rig's clock (``rig_time_s``) and on the wall (``wall_time_s``); a session metered
before that was recorded says it does not count them, rather than a total that leaves them
out unsaid.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from rti_rig.cli.session import _time_line


def _folder(runs: int, evidence: dict[str, Any] | None) -> SimpleNamespace:
    provenance = {} if evidence is None else {"exposure": evidence}
    manifest = {
        "schedule": {"provenance": provenance},
        "timing": {"rig_time_s": 100.0, "wall_time_s": 5.0, "runs": runs},
        "runs": [{"rig_time_s": 50.0}] * runs,
    }
    return SimpleNamespace(manifest=manifest, root=None)


RESULT = SimpleNamespace(rig_time_s=57.2, wall_time_s=2.2)
METERED = {"metering_shots": 7, "rig_time_s": 8.4, "wall_time_s": 0.5}


def test_a_metered_run_counts_its_metering_shots_and_says_so() -> None:
    assert _time_line(_folder(1, METERED), RESULT, dry=True) == (
        "Session time on the real rig: 65.6 s including 7 metering shots (metering 8.4 s, "
        "simulated in 2.7 s)"
    )
    assert _time_line(_folder(1, METERED), RESULT, dry=False) == (
        "Session time on the real rig: 65.6 s including 7 metering shots (metering 8.4 s)"
    )


def test_a_resumed_metered_session_counts_the_metering_once_beside_its_runs() -> None:
    assert _time_line(_folder(2, METERED), RESULT, dry=True) == (
        "Session time on the real rig: 108.4 s over 2 runs including 7 metering shots (this "
        "run 57.2 s, metering 8.4 s, simulated in 2.2 s)"
    )


def test_a_session_not_metered_or_metered_before_its_time_was_recorded() -> None:
    assert _time_line(_folder(1, None), RESULT, dry=True) == (
        "Session time on the real rig: 57.2 s (simulated in 2.2 s)"
    )
    older = {"metering_shots": 7, "test_exposures_by_light_s": [[0.1, 0.08]]}
    assert _time_line(_folder(1, older), RESULT, dry=True) == (
        "Session time on the real rig: 57.2 s, not counting 7 metering shots (simulated in 2.2 s)"
    )
