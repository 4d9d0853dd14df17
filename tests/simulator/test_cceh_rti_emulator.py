"""The cceh/rti firmware emulator and the PC-sync camera that fires it, on virtual time.

Facts from cceh/rti ``firmware/rti.cpp``: each flash pulse lights the programmed LED and steps;
edges within 2 ms of the previous one are ignored; 4 s after a flash the LEDs go off; after the
60th LED every flash re-lights the last one; a long press of start rewinds; the pilot light
leaves every LED programmed.
"""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.simulator.domes.cceh_rti import LED_COUNT, TIMEOUT_S, CcehRtiFirmware
from rti_rig.simulator.flash_sync_camera import FlashSyncCamera, SyncFault
from rti_rig.simulator.sim_scene import renderer_for


def test_each_pulse_lights_the_next_led_only_while_the_contact_is_closed() -> None:
    fw = CcehRtiFirmware()
    for k in range(3):
        fw.pulse(1.0 + k, 0.1)
    for k in range(3):
        assert fw.lit_at(1.0 + k + 0.05) == {k}
        assert fw.lit_at(1.0 + k + 0.5) == frozenset()
    assert fw.led_index == 3


def test_a_bounce_inside_the_debounce_is_ignored_a_longer_one_steps_twice() -> None:
    fw = CcehRtiFirmware()
    fw.flash_edge(1.0, True)
    fw.flash_edge(1.001, False)  # 1 ms: within the 2 ms debounce
    fw.flash_edge(1.002, True)
    fw.flash_edge(1.1, False)
    assert fw.led_index == 1 and fw.lit_at(1.05) == {0}
    fw.flash_edge(2.0, True)
    fw.flash_edge(2.0035, False)  # 3.5 ms: acted on
    fw.flash_edge(2.007, True)  # ...and so is the re-close: a second step
    fw.flash_edge(2.1, False)
    assert fw.led_index == 3
    assert fw.lit_at(2.001) == {1} and fw.lit_at(2.05) == {2}


def test_the_firmware_switches_off_4_s_after_a_flash_held_on() -> None:
    fw = CcehRtiFirmware()
    fw.pulse(10.0, 6.0)  # the camera holds its sync contact for 6 s
    assert fw.lit_at(10.0 + TIMEOUT_S - 0.01) == {0}
    assert fw.lit_at(10.0 + TIMEOUT_S + 0.001) == frozenset()
    assert (10.0 + TIMEOUT_S, "timeout: off") in fw.events
    assert fw.lit_during(10.0, 16.0) == {0: pytest.approx(TIMEOUT_S)}


def test_after_its_last_led_every_flash_relights_the_last_one() -> None:
    fw = CcehRtiFirmware()
    for k in range(LED_COUNT + 2):
        fw.pulse(float(k), 0.1)
    assert fw.lit_at(LED_COUNT - 1 + 0.05) == {LED_COUNT - 1}
    assert fw.lit_at(LED_COUNT + 0.05) == {LED_COUNT - 1}
    assert fw.lit_at(LED_COUNT + 1 + 0.05) == {LED_COUNT - 1}


def test_long_press_rewinds_and_the_pilot_light_leaves_every_led_programmed() -> None:
    fw = CcehRtiFirmware()
    fw.pulse(0.0, 0.1)
    fw.pulse(1.0, 0.1)
    fw.long_press(2.0)
    fw.pulse(4.0, 0.1)
    assert fw.lit_at(4.05) == {0}
    fw.short_press(5.0)  # pilot on: every LED
    assert len(fw.lit_at(5.1)) == LED_COUNT
    fw.short_press(6.0)  # pilot off, but the pattern stays programmed
    fw.pulse(7.0, 0.1)
    assert len(fw.lit_at(7.05)) == LED_COUNT


def test_a_power_cycle_forgets_the_count_and_the_next_flash_lights_led_0() -> None:
    """``led_index`` is zeroed and LED 0 programmed at every start (firmware/rti.cpp), even
    with a flash timeout pending and a pilot pattern programmed before the power went."""
    fw = CcehRtiFirmware()
    for k in range(3):
        fw.pulse(float(k), 0.1)
    fw.short_press(3.0)  # pilot on: every LED lit and programmed
    fw.power_cycle(4.0)
    assert fw.lit_at(4.0) == set() and fw.led_index == 0
    fw.pulse(5.0, 0.1)
    fw.pulse(6.0, 0.1)
    assert fw.lit_at(5.05) == {0} and fw.lit_at(6.05) == {1}


def _camera(faults=(), exposure_s=0.05):  # type: ignore[no-untyped-def]
    clock = VirtualClock()
    dirs = direction_from_az_el(45 + 360 * np.arange(8) / 8, np.full(8, 40.0))
    cam = FlashSyncCamera(
        renderer_for("relief", 32, 32, 0),
        CcehRtiFirmware(),
        dirs,
        clock,
        faults=tuple(faults),
        reference_exposure_s=exposure_s,
        noise=False,
    )
    cam.connect()
    return cam, clock


def test_the_camera_fires_the_dome_at_each_exposure() -> None:
    cam, _ = _camera()
    frames = [cam.capture(0.05) for _ in range(3)]
    for k, (n, t0, t1) in enumerate(cam.windows):
        assert n == k + 1
        assert cam.dome.lit_during(t0, t1) == {k: pytest.approx(0.05)}
    assert all(f.pixels.max() > 1000 for f in frames)


def test_a_missed_pulse_gives_a_dark_image_and_no_step() -> None:
    cam, _ = _camera([SyncFault(2, "missed_pulse")])
    cam.capture(0.05)
    dark = cam.capture(0.05)
    cam.capture(0.05)
    assert dark.pixels.max() == 0
    _, t0, t1 = cam.windows[2]
    assert cam.dome.lit_during(t0, t1) == {1: pytest.approx(0.05)}  # one LED behind


def test_a_double_step_lights_the_image_mostly_with_the_next_led() -> None:
    cam, _ = _camera([SyncFault(2, "double_step")])
    cam.capture(0.05)
    cam.capture(0.05)
    cam.capture(0.05)
    _, t0, t1 = cam.windows[1]
    seconds = cam.dome.lit_during(t0, t1)
    assert set(seconds) == {1, 2} and seconds[2] > 10 * seconds[1]
    _, t0, t1 = cam.windows[2]
    assert set(cam.dome.lit_during(t0, t1)) == {3}  # one LED ahead from then on


def test_an_exposure_longer_than_the_timeout_is_lit_only_4_s() -> None:
    cam, clock = _camera(exposure_s=5.0)
    lit = cam.capture(5.0)
    _, t0, t1 = cam.windows[0]
    assert cam.dome.lit_during(t0, t1) == {0: pytest.approx(TIMEOUT_S)}
    full, _ = _camera(exposure_s=5.0)
    ref = full.capture(4.0)  # the same sensor, a 4 s exposure: the same light
    ratio = lit.pixels.astype(float).sum() / ref.pixels.astype(float).sum()
    assert ratio == pytest.approx(1.0, rel=0.01)
    assert clock.now() >= 5.0
