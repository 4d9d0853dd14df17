"""The simulated camera's memory: a frame is rendered and exposed a band of rows at a time.

A 24 MP simulated DSLR session peaked at 3.8 GB because the relief scene kept its normals and
albedo as whole float64 planes and the sensor chain made half a dozen whole-image float64
temporaries. The measure here is tracemalloc's peak (numpy reports its buffers to it) in units
of one whole-image float64 radiance array: a bounded count, independent of machine speed.
The images themselves must not change: the banded pipeline is compared, bit for bit, with the
whole-image formulas it replaced.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.simulator import sim_scene
from rti_rig.simulator.sim_camera import SimulatedCamera
from rti_rig.simulator.sim_lights import LightState
from rti_rig.simulator.sim_scene import lambert_radiance, relief_scene, renderer_for

H, W = 700, 600  # several bands of rows, and not a multiple of the band height
RADIANCE_BYTES = H * W * 3 * 8
LIGHT = np.array([0.3, -0.2, 0.93]) / np.linalg.norm([0.3, -0.2, 0.93])


@pytest.fixture(autouse=True)
def _small_bands(monkeypatch: pytest.MonkeyPatch) -> None:
    """Bands of 40 rows: many bands in a small test image, so a band's own temporaries are a
    small part of it, as in a 24 MP frame (~90 bands of 43 rows)."""
    monkeypatch.setattr(sim_scene, "BAND_PIXELS", 40 * W, raising=False)
    # and no whole-image planes kept: the test's small image stands for a 24 MP one
    monkeypatch.setattr(sim_scene, "CACHED_PIXELS", 0, raising=False)


@pytest.fixture(params=["banded planes", "kept planes"])
def planes(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """A small image keeps its normals and albedo (``CACHED_PIXELS``); a large one makes them
    band by band. Both must give the whole-image formula's pixels."""
    if request.param == "kept planes":
        monkeypatch.setattr(sim_scene, "CACHED_PIXELS", H * W)
    return str(request.param)


def _peak_while(fn):  # type: ignore[no-untyped-def]
    """``fn()``'s result and the most memory traced at once during it, above what was held."""
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        result = fn()
        peak = tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()
    return result, peak


def _state(direction, intensity):  # type: ignore[no-untyped-def]
    state = LightState()
    state.direction, state.intensity = direction, intensity
    return state


def test_building_the_relief_renderer_holds_less_than_one_radiance_image():
    render, peak = _peak_while(lambda: renderer_for("relief", H, W, seed=0))
    # the height field (a third of a radiance image) and a band's temporaries; whole-image
    # planes held 0.9 before the first capture and the scene kept 1.3 for good
    assert peak < 0.7 * RADIANCE_BYTES, peak / RADIANCE_BYTES
    assert render is not None


def test_a_capture_holds_less_than_one_and_a_half_radiance_images():
    render = renderer_for("relief", H, W, seed=0)
    camera = SimulatedCamera(
        render, _state(LIGHT, 1.0), VirtualClock(), reference_exposure_s=0.05, seed=1
    )
    camera.connect()
    frame, peak = _peak_while(lambda: camera.capture(0.05))
    # the Poisson counts (float32, half an image), the uint16 output (a quarter) and a band's
    # temporaries (~1.1 in all); the whole-image float64 passes held 2.8
    assert peak < 1.5 * RADIANCE_BYTES, peak / RADIANCE_BYTES
    assert frame.pixels.shape == (H, W, 3)


def test_the_banded_relief_renders_the_whole_image_formula_bit_for_bit(planes):
    render = renderer_for("relief", H, W, seed=2)
    assert (render._planes is not None) == (planes == "kept planes")  # the case is the one named
    scene = relief_scene(H, W, seed=2)
    for direction in (LIGHT, np.array([0.0, 0.0, 1.0]), np.array([-0.97, 0.0, 0.243])):
        np.testing.assert_array_equal(
            render(direction, 0.7), lambert_radiance(scene, direction, 0.7)
        )
    np.testing.assert_array_equal(render(None, 0.0), np.zeros((H, W, 3)))


@pytest.mark.parametrize("noise", [True, False])
@pytest.mark.parametrize("ambient, exposure_s", [(0.0, 0.05), (0.03, 0.02), (0.0, 4.0)])
def test_the_banded_sensor_gives_the_whole_image_pixels_bit_for_bit(noise, ambient, exposure_s):
    """The sensor chain as one whole-image pass (the formula the bands replaced): all Poisson
    draws, then all read-noise draws, from the camera's own seeded generator."""
    scene = relief_scene(H, W, seed=0)
    state = _state(LIGHT, 0.8)
    camera = SimulatedCamera(
        renderer_for("relief", H, W, seed=0),
        state,
        VirtualClock(),
        reference_exposure_s=0.05,
        ambient=ambient,
        noise=noise,
        seed=4,
    )
    camera.connect()
    got = camera.capture(exposure_s).pixels

    full_well = 20000.0
    electrons = (lambert_radiance(scene, LIGHT, 0.8) + ambient) * (
        0.75 * full_well / 0.05 * exposure_s
    )
    rng = np.random.default_rng(camera._noise_key(exposure_s))
    if noise:
        electrons = rng.poisson(np.clip(electrons, 0.0, None)).astype(np.float64)
        electrons += rng.normal(0.0, 3.0, electrons.shape)
    electrons = np.clip(electrons, 0.0, full_well)
    want = np.round(electrons * (65535 / full_well)).astype(np.uint16)
    np.testing.assert_array_equal(got, want)
    if exposure_s > 1:
        assert (got == 65535).any()  # the clip at the full well is exercised
