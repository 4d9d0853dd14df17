"""On a dome whose LEDs differ, the exposure is checked at several lights, brightest-ranked first.

Metering at the one light nearest the zenith clipped 7 of 48 images of the shipped emulated card
dome (uneven LEDs): another light was brighter. These tests pin the ranking, the order the
lights are lit and switched off in, that a brighter light shortens the exposure (never
lengthens it), the evidence recorded, and that a stop or an error while checking tears down as
the first metering does.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from conftest import SMALL_DOME, write_config

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.core.errors import DeviceError
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.core.schedule import LightSchedule, LightStep
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.exposure_policy import (
    Recheck,
    brightest_step,
    fix_session_exposure,
    metering_steps,
)


def _step(az: float, el: float, led: int, intensity: float = 1.0) -> LightStep:
    d = direction_from_az_el(az, el)
    return LightStep((float(d[0]), float(d[1]), float(d[2])), led, intensity=intensity)


def test_lights_are_ranked_by_what_a_level_object_receives_once_each() -> None:
    schedule = LightSchedule(
        steps=(
            _step(0, 20, 0),
            _step(0, 90, 1, intensity=0.5),  # the zenith, dimmed: 0.5
            _step(90, 60, 2),  # sin 60° = 0.87
            _step(180, 60, 3),  # a tie with LED 2: plan order
            _step(90, 60, 2),  # LED 2 again: ranked once
            _step(270, 45, 4),  # 0.71
        )
    )
    assert metering_steps(schedule, 6) == [2, 3, 5, 1, 0]
    assert metering_steps(schedule, 2) == [2, 3]
    assert metering_steps(schedule) == [2] and brightest_step(schedule) == 2


class Choice:
    """A metering's choice as the policy reads it."""

    def __init__(self, exposure_s: float, tested: tuple[float, ...]) -> None:
        self.exposure_s = exposure_s
        self.test_exposures_s = tested

    def to_manifest(self) -> dict[str, Any]:
        return {"exposure_s": self.exposure_s, "test_exposures_s": list(self.test_exposures_s)}


def _rig_and_plan(tmp_path: Path):  # type: ignore[no-untyped-def]
    rig = build_rig(load_rig_config(write_config(tmp_path, SMALL_DOME)))
    return rig, plan_uniform(rig.geometry, 12)


def _logged(rig) -> list[object]:  # type: ignore[no-untyped-def]
    """The lights' calls in order: an LED lit, or "off"."""
    log: list[object] = []
    real_set, real_off = rig.lighting.set, rig.lighting.off
    rig.lighting.set = lambda step: (log.append(step.led), real_set(step))[1]
    rig.lighting.off = lambda: (log.append("off"), real_off())[1]
    return log


def test_a_brighter_light_among_those_checked_shortens_the_exposure(tmp_path: Path) -> None:
    rig, schedule = _rig_and_plan(tmp_path)
    log = _logged(rig)
    order = metering_steps(schedule, 6)
    leds = [schedule.steps[i].led for i in order]
    # the light each check finds: the third-ranked is 1.6× brighter (a shorter exposure), the
    # fifth darker (it would allow a longer one, which must not be taken)
    found = {leds[2]: Choice(0.0125, (0.02, 0.005, 0.0125)), leds[4]: Choice(0.03, (0.0125,))}
    checked: list[tuple[object, float]] = []

    def meter(camera, start_s: float) -> Choice:  # type: ignore[no-untyped-def]
        return Choice(0.02, (start_s, 0.02))

    def recheck(camera, exposure_s: float) -> Recheck:  # type: ignore[no-untyped-def]
        lit = rig.lighting.source.lit
        checked.append((lit, exposure_s))
        choice = found.get(lit)
        return Recheck((exposure_s,) if choice is None else choice.test_exposures_s, choice)

    fixed = fix_session_exposure(rig, schedule, meter, recheck, probes=6)
    assert checked == [
        (leds[1], 0.02),
        (leds[2], 0.02),
        (leds[3], 0.0125),
        (leds[4], 0.0125),
        (leds[5], 0.0125),
    ]
    # each light is switched off before the next one lights, and the last one by the teardown
    assert log == [leds[0], *(x for led in leds[1:] for x in ("off", led))]
    assert rig.lighting.source.lit is None  # type: ignore[attr-defined]
    assert {s.exposure_s for s in fixed.steps} == {0.0125}
    evidence = fixed.provenance["exposure"]
    assert evidence["exposure_s"] == 0.0125
    assert evidence["metered_at_step"] == order[2] + 1
    assert evidence["lights_metered_at_steps"] == [i + 1 for i in order]
    assert evidence["test_exposures_by_light_s"] == [
        [0.05, 0.02],
        [0.02],
        [0.02, 0.005, 0.0125],
        [0.0125],
        [0.0125],
        [0.0125],
    ]
    assert evidence["metering_shots"] == 9


def test_without_a_recheck_one_light_is_metered_as_before(tmp_path: Path) -> None:
    rig, schedule = _rig_and_plan(tmp_path)
    log = _logged(rig)
    fixed = fix_session_exposure(rig, schedule, lambda camera, start_s: Choice(0.02, ()), None, 6)
    assert log == [schedule.steps[brightest_step(schedule)].led]
    evidence = fixed.provenance["exposure"]
    assert evidence["lights_metered_at_steps"] == [brightest_step(schedule) + 1]
    assert evidence["metering_shots"] == 1
    with pytest.raises(ValueError, match="probes must be at least 1"):
        fix_session_exposure(rig, schedule, lambda camera, start_s: Choice(0.02, ()), None, 0)


@pytest.mark.parametrize("raised", [KeyboardInterrupt, DeviceError])
def test_a_stop_or_an_error_while_checking_tears_down_and_says_what_it_could_not(
    tmp_path: Path, raised: type[BaseException]
) -> None:
    """A Ctrl-C or a device error at the third light: the lights are made safe and the devices
    closed, and what the teardown could not do travels with it, as for the first metering."""
    rig, schedule = _rig_and_plan(tmp_path)
    real_safe, closed = rig.lighting.safe, []
    rig.lighting.safe = lambda emergency=False: (real_safe(), ["all LEDs off: no reply"])[1]  # type: ignore[method-assign]
    real_close = rig.camera.close
    rig.camera.close = lambda: (closed.append("camera"), real_close())[1]  # type: ignore[method-assign]
    checks = []

    def recheck(camera, exposure_s: float) -> Recheck:  # type: ignore[no-untyped-def]
        checks.append(exposure_s)
        if len(checks) == 2:
            raise raised() if raised is KeyboardInterrupt else DeviceError("dome", "no reply")
        return Recheck((exposure_s,))

    with pytest.raises(raised) as stopped:
        fix_session_exposure(rig, schedule, lambda c, s: Choice(0.02, (s,)), recheck, probes=6)
    assert len(checks) == 2
    assert stopped.value.teardown_failures == ["all LEDs off: no reply"]  # type: ignore[attr-defined]
    assert rig.lighting.source.lit is None  # type: ignore[attr-defined]
    assert closed == ["camera"]


def test_with_a_shot_per_lighting_each_test_shot_is_lit_again_and_the_time_recorded(
    tmp_path: Path,
) -> None:
    """A timed firmware's LED goes dark by itself a fixed time after it lit (RTIPy: 2 s), and a
    series of test shots under one lighting outlasts that window (about 1.1 s a shot): the
    third shot of a series had been dark. With ``shot_per_lighting`` every shot after the
    first is preceded by the light's off (on such a firmware: its window waited out) and the
    light lit again, at every light metered; each light's first shot is under the lighting
    that opened it."""
    rig, schedule = _rig_and_plan(tmp_path)
    log = _logged(rig)
    real_capture = rig.camera.capture

    def capture(exposure_s: float):  # type: ignore[no-untyped-def]
        log.append(("shot", rig.lighting.source.lit))  # type: ignore[attr-defined]
        return real_capture(exposure_s)

    rig.camera.capture = capture  # type: ignore[method-assign]

    def meter(camera, start_s: float) -> Choice:  # type: ignore[no-untyped-def]
        for t in (start_s, start_s / 4, 0.02):
            camera.capture(t)
        return Choice(0.02, (start_s, start_s / 4, 0.02))

    def recheck(camera, exposure_s: float) -> Recheck:  # type: ignore[no-untyped-def]
        camera.capture(exposure_s)
        camera.capture(exposure_s)
        return Recheck((exposure_s, exposure_s))

    before = rig.clock.now()
    fixed = fix_session_exposure(rig, schedule, meter, recheck, 2, shot_per_lighting=True)
    first, second = (schedule.steps[i].led for i in metering_steps(schedule, 2))
    assert log == [
        first,
        ("shot", first),
        *(x for _ in range(2) for x in ("off", first, ("shot", first))),
        "off",
        second,
        ("shot", second),
        "off",
        second,
        ("shot", second),
    ]
    evidence = fixed.provenance["exposure"]
    assert evidence["shot_per_lighting"] is True
    assert evidence["metering_shots"] == 5
    # the metering's time on the rig's clock: what the session's time line adds
    assert evidence["rig_time_s"] == pytest.approx(rig.clock.now() - before)
    assert evidence["rig_time_s"] > 5 * (0.3 + 0.7)  # five shots' readout and transfer at least

    # without it (a dome whose LEDs stay lit until told): one lighting per light, as before
    log.clear()
    fixed = fix_session_exposure(rig, schedule, meter, recheck, 2)
    assert log == [first, *[("shot", first)] * 3, "off", second, *[("shot", second)] * 2]
    assert fixed.provenance["exposure"]["shot_per_lighting"] is False
