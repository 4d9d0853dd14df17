"""The QA's margin for a dark light near the surface is the fit's real tilt under uneven lights.

:func:`surface_margin_deg` propagates the lights' gain scatter through least-squares
photometric stereo to first order; checked here against the tilt such gains really give a
fitted normal (Monte Carlo), on the 12-light fibonacci dome over a plane tilted 50°.
"""

from __future__ import annotations

import numpy as np

from rti_rig.reconstruct.qa_surface import SURFACE_MARGIN_SD, surface_margin_deg


def _fibonacci(n: int, min_elevation_deg: float = 15.0) -> np.ndarray:
    z0 = np.sin(np.radians(min_elevation_deg))
    i = np.arange(n)
    z = z0 + (1 - z0) * (i + 0.5) / n
    phi = i * np.pi * (3 - np.sqrt(5))
    r = np.sqrt(1 - z**2)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def test_the_margin_is_twice_the_tilt_uneven_lights_give_the_fit() -> None:
    lights = _fibonacci(12)
    tilt = np.radians(50.0)
    normal = np.array([np.sin(tilt) * np.cos(1.0), np.sin(tilt) * np.sin(1.0), np.cos(tilt)])
    above = lights @ normal > 0
    rng = np.random.default_rng(0)
    errors = []
    for _ in range(4000):
        gains = np.exp(0.2 * rng.standard_normal(above.sum()))
        image = gains * (lights[above] @ normal)
        b = np.linalg.lstsq(lights[above], image, rcond=None)[0]
        errors.append(np.degrees(np.arccos(np.clip(b @ normal / np.linalg.norm(b), -1, 1))))
    rms = float(np.sqrt(np.mean(np.square(errors))))
    margin = surface_margin_deg(lights, normal, 0.2)
    assert abs(margin / SURFACE_MARGIN_SD - rms) < 0.15 * rms, (margin, rms)


def test_even_lights_or_no_measured_scatter_leave_no_margin() -> None:
    lights = _fibonacci(12)
    up = np.array([0.0, 0.0, 1.0])
    assert surface_margin_deg(lights, up, float("nan")) == 0.0
    assert surface_margin_deg(lights, up, 0.0) == 0.0
    assert surface_margin_deg(lights, np.zeros(3), 0.2) == 0.0
    # fewer lights above the surface place it less surely
    assert surface_margin_deg(lights[::2], up, 0.2) > surface_margin_deg(lights, up, 0.2) > 0.0
