"""A refused dome step is named by its LED's number and direction, not the dome's id for it.

The preview's note says "LED 36 (az 112.5°, el 55.0°)", while a refusal of the same step read
"step 1 (led_036): ...": the dome's machine-readable name for the LED (a step's ``label``,
which the manifest keeps as it is). A name the user gave (a dome ``.lp``'s image name) is
still said beside the number.
"""

from __future__ import annotations

from dataclasses import replace

import pytest
from conftest import CONFIGS

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.core.errors import ScheduleError
from rti_rig.core.schedule import LightSchedule
from rti_rig.planner.preview_shot import preview_schedule
from rti_rig.runtime.controller import validate_schedule


def _refusal(label: str | None = None) -> tuple[str, LightSchedule]:
    with build_rig(load_rig_config(CONFIGS / "simulated_dome.toml")) as rig:
        schedule, _ = preview_schedule(rig.geometry, (100.0, 50.0))  # type: ignore[arg-type]
        step = schedule.steps[0]
        step = replace(step, exposure_s=100.0, label=step.label if label is None else label)
        with pytest.raises(ScheduleError) as refused:
            validate_schedule(rig, LightSchedule([step]))
    return str(refused.value), schedule


def test_the_preview_step_is_refused_naming_its_led_by_number() -> None:
    said, schedule = _refusal()
    assert schedule.steps[0].label == "led_036"  # the manifest's id, kept
    assert "step 1 (LED 36, az 112.5°, el 55.0°): exposure 100.0 s outside" in said, said
    assert "led_0" not in said, said


def test_a_name_the_user_gave_the_led_is_said_beside_its_number() -> None:
    said, _ = _refusal("led_36.jpg")
    assert "step 1 (LED 36, led_36.jpg, az 112.5°, el 55.0°)" in said, said
