"""The sentence on the lights after an early stop says only what is so.

Found by an audit: a replayed acquisition's emergency stop said "lights were switched off"
(a replay has no lights), and an arm's said "(see any teardown problem above)" with nothing
above it.
"""

from __future__ import annotations

from pathlib import Path

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.app.usecases.safe_state import lights_state

REPO = Path(__file__).resolve().parents[2]


def test_a_replay_has_no_lights_to_switch_off() -> None:
    rig = build_rig(load_rig_config(REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"))
    with rig:
        assert lights_state(rig) == "a replayed acquisition has no lights to switch off"


def test_an_arm_points_at_teardown_problems_only_when_there_are_some() -> None:
    rig = build_rig(load_rig_config(REPO / "rig_configs" / "virtual_arm.toml"))
    with rig:
        assert lights_state(rig) == "lamp off and stop were requested"
        assert lights_state(rig, teardown_failed=True).endswith("(see the teardown problems above)")
