"""The simulated camera's exposure is the modelled one from its trigger, whatever rendering costs.

Rendering had come first and the exposure after it, so on the real clock of a self-timed dome
(RTIPy's LED goes dark 2 s after it lit) the render's ~0.1 s of CPU pushed the whole exposure
later into the LED's window: an exposure the window admits (0.88 s on emulated_rtipy.toml) had
every capture of a dry run refused as outlasting the LED. Here the render's cost is modelled on
the camera's own clock (virtual, so nothing depends on the machine's load), and the last test
runs the real emulated RTIPy board with a renderer slowed to the whole readout and transfer.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from conftest import CONFIGS
from numpy.typing import NDArray

from rti_rig.app import compose
from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.core.clock import VirtualClock
from rti_rig.planner.uniform import plan_uniform
from rti_rig.simulator.sim_camera import SimulatedCamera
from rti_rig.simulator.sim_lights import LightState

EXPOSURE_S, READOUT_S, TRANSFER_S = 0.88, 0.3, 0.7
LIGHT = np.array([0.0, 0.6, 0.8])


def flat(direction: NDArray[np.float64] | None, intensity: float) -> NDArray[np.float64]:
    """A small grey card: radiance follows the light's intensity, black without a light."""
    return np.full((6, 5, 3), 0.0 if direction is None else 0.5 * intensity)


def costing(clock: VirtualClock, render_s: float):  # type: ignore[no-untyped-def]
    """``flat``, taking ``render_s`` of the camera's clock to render (the simulator's CPU)."""

    def render(direction: NDArray[np.float64] | None, intensity: float) -> NDArray[np.float64]:
        clock.sleep(render_s)
        return flat(direction, intensity)

    return render


class TimedLed:
    """A light that goes dark by itself at ``off_at`` on the clock (RTIPy's timed LED), and
    whose reading takes ``read_s`` (an emulated board's link is first run up to now)."""

    def __init__(self, clock: VirtualClock, off_at: float, read_s: float = 0.0) -> None:
        self._clock, self.off_at, self._read_s = clock, off_at, read_s

    def _on(self) -> bool:
        self._clock.sleep(self._read_s)
        return self._clock.now() < self.off_at

    @property
    def direction(self) -> NDArray[np.float64] | None:
        return LIGHT if self._on() else None

    @property
    def intensity(self) -> float:
        return 1.0 if self._on() else 0.0


def camera(render, state, clock: VirtualClock) -> SimulatedCamera:  # type: ignore[no-untyped-def]
    cam = SimulatedCamera(
        render,
        state,
        clock,
        reference_exposure_s=2.0,
        readout_s=READOUT_S,
        transfer_s=TRANSFER_S,
        seed=3,
    )
    cam.connect()
    return cam


@pytest.mark.parametrize("render_s", [0.0, 0.12, 0.95])
def test_the_exposure_is_the_modelled_one_from_the_trigger_and_rendering_hides_in_readout(
    render_s: float,
) -> None:
    clock = VirtualClock(100.0)
    cam = camera(costing(clock, render_s), LightState(LIGHT, 1.0), clock)
    cam.capture(EXPOSURE_S)
    trigger, exposed, delivered = cam.exposures[-1]
    assert trigger == 100.0
    assert exposed == pytest.approx(100.0 + EXPOSURE_S, abs=1e-9)
    # readout + transfer (1 s) is longer than the render: the frame comes when a camera's would
    assert delivered == pytest.approx(exposed + READOUT_S + TRANSFER_S, abs=1e-9)
    assert clock.now() == delivered


def test_a_render_longer_than_readout_and_transfer_delays_the_frame_not_the_exposure() -> None:
    clock = VirtualClock(5.0)
    cam = camera(costing(clock, 1.6), LightState(LIGHT, 1.0), clock)
    cam.capture(EXPOSURE_S)
    trigger, exposed, delivered = cam.exposures[-1]
    assert (trigger, exposed) == pytest.approx((5.0, 5.0 + EXPOSURE_S), abs=1e-9)
    assert delivered == pytest.approx(exposed + 1.6, abs=1e-9)


def test_time_spent_reading_the_light_lies_inside_the_exposure_not_after_it() -> None:
    """An emulated board's light is read after its link has caught up (time on the clock)."""
    clock = VirtualClock()
    cam = camera(flat, TimedLed(clock, off_at=60.0, read_s=0.03), clock)
    cam.capture(EXPOSURE_S)
    trigger, exposed, _ = cam.exposures[-1]
    assert exposed - trigger == pytest.approx(EXPOSURE_S, abs=1e-9)


def test_an_led_going_dark_as_the_exposure_ends_lit_the_image_and_outlived_the_exposure() -> None:
    """The image is of the light on at the trigger, rendered after the exposure: a timed LED
    that is dark by then still lit the whole image, bit for bit the image under a steady one."""
    clock = VirtualClock()
    led = TimedLed(clock, off_at=EXPOSURE_S + 1e-6)
    cam = camera(costing(clock, 0.12), led, clock)
    timed = cam.capture(EXPOSURE_S)
    _, exposed, _ = cam.exposures[-1]
    assert exposed <= led.off_at  # the LED was on through the whole exposure
    steady = camera(flat, LightState(LIGHT, 1.0), VirtualClock()).capture(EXPOSURE_S)
    np.testing.assert_array_equal(timed.pixels, steady.pixels)
    assert timed.pixels.mean() > 1000  # lit, not the sensor's noise alone


@pytest.mark.slow  # the emulated RTIPy board runs in real time: a connect and one LED window
def test_on_the_emulated_rtipy_a_slow_render_leaves_the_shot_inside_the_led_window(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The real scripted driver, pyserial and the RTIPy emulator on a pty, the camera's render
    slowed by 1 s of real time (all of the shipped readout + transfer). The exposure begins
    at the trigger, inside the LED's on-time as the board recorded it, and the all-off finds
    the capture ended inside the window. Rendered first, the exposure had begun 1 s late and
    the capture ended ~0.2 s after the LED went dark: the all-off refused it."""
    from rti_rig.core.dome_link import DomeLedError

    real = compose.scene_renderer

    def slowed(loaded):  # type: ignore[no-untyped-def]
        render = real(loaded)

        def slow(direction, intensity):  # type: ignore[no-untyped-def]
            time.sleep(1.0)
            return render(direction, intensity)

        return slow

    monkeypatch.setattr(compose, "scene_renderer", slowed)
    with build_rig(load_rig_config(CONFIGS / "emulated_rtipy.toml")) as rig:
        board = rig.emulator  # type: ignore[attr-defined]
        cam = rig.camera
        assert isinstance(cam, SimulatedCamera)
        rig.lighting.connect()
        cam.connect()
        rig.lighting.set(plan_uniform(rig.geometry, 8).steps[0])
        rig.clock.sleep(rig.timing.settle_s)
        frame = cam.capture(0.05)
        trigger, exposed, _ = cam.exposures[-1]
        try:
            rig.lighting.off()  # refuses a capture that ended after the LED went dark
        except DomeLedError as exc:
            pytest.fail(f"the slow render stretched the lit window: {exc}")
        assert board.lit == frozenset()  # the board run up to now: past the LED's window
        lit_from = [t for t, leds in board.timeline if leds == frozenset({0})]
        dark_from = [t for t, leds in board.timeline if t > lit_from[0] and not leds]
        assert lit_from and dark_from, board.timeline
        assert lit_from[0] <= trigger < exposed <= dark_from[0], (trigger, exposed, board.timeline)
        assert frame.pixels.mean() > 1000  # lit (about 7000): not the sensor's noise alone
