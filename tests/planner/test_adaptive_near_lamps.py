"""Lamps near the object in the stop's simulation (planner/adaptive_bias.py, ``NearLamps``).

A point lamp reaches each pixel from its own direction and at its own distance; the robust fit
reads one direction per light. Rendered so, the simulated error carries the bias a session
under such lamps measures; at the extremes (a lamp far away, the frame's centre) it is the
directional rendering exactly."""

from __future__ import annotations

import numpy as np
import pytest
from adaptive_states import open_model

from rti_rig.app.usecases.adaptive import robust_fit
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.planner.adaptive_bias import NearLamps, ObjectModel, render, simulate_error_deg


def _model(p: int = 400, spec: float = 0.0) -> ObjectModel:
    return open_model(0, p, spec)


def _field(p: int, width_mm: float, seed: int = 1) -> np.ndarray:
    """``p`` pixel positions spread over a square field ``width_mm`` wide."""
    return np.random.default_rng(seed).uniform(-width_mm / 2, width_mm / 2, (p, 2))


LIGHTS = np.array(
    [direction_from_az_el(az, el) for az, el in ((0, 30), (90, 40), (180, 30), (270, 40), (45, 60))]
)


@pytest.mark.parametrize("spec", [0.0, 0.3])
def test_a_far_lamp_renders_as_a_direction(spec: float) -> None:
    model = _model(spec=spec)
    pix = np.arange(len(model.normals))
    far = NearLamps(1e9, _field(len(pix), 50.0))
    directional = render(model, LIGHTS, pix)
    assert np.allclose(render(model, LIGHTS, pix, far), directional, atol=1e-7)


def test_the_frames_centre_sees_the_lamps_direction() -> None:
    model = _model(spec=0.3)
    pix = np.arange(len(model.normals))
    near = NearLamps(100.0, np.zeros((len(pix), 2)))
    assert np.allclose(render(model, LIGHTS, pix, near), render(model, LIGHTS, pix))


def test_an_off_centre_pixel_is_lit_from_its_own_direction_and_distance() -> None:
    """One pixel facing the camera, 30 mm to the right of the centre, a lamp 100 mm away over
    the centre's +x horizon at 30°: its direction and inverse square from the pixel."""
    model = _model(p=1)
    model.normals[:] = [0.0, 0.0, 1.0]
    light = direction_from_az_el(0.0, 30.0)[None]
    near = NearLamps(100.0, np.array([[30.0, 0.0]]))
    to = 100.0 * light[0] - [30.0, 0.0, 0.0]
    r = np.linalg.norm(to)
    expected = model.albedo[0] * (to[2] / r) * (100.0 / r) ** 2
    got = render(model, light, np.array([0]), near)[0, 0]
    assert got == pytest.approx(expected, rel=1e-12)
    assert got > render(model, light, np.array([0]))[0, 0] * 1.2  # nearer, and higher: brighter


def test_near_lamps_cost_the_fit_more_as_they_come_closer() -> None:
    """The simulated error grows as the lamps come closer to a 20 mm field, and each geometry
    is rendered on its own: the model's cache keeps them apart (the nearest rendered first, so
    that a shared key would hand its columns to every later call)."""
    model = _model()
    xy = _field(len(model.normals), 20.0)
    distances = (100.0, 400.0, 2000.0, None)
    errors = [
        simulate_error_deg(model, LIGHTS, robust_fit, near=None if d is None else NearLamps(d, xy))
        for d in distances
    ]
    assert errors == sorted(errors, reverse=True), errors
    assert errors[0] > 3 * errors[3], errors
