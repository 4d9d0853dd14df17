"""Property tests: invariants that must hold for any well-posed input."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rti_rig.core.geometry import direction_from_az_el
from rti_rig.reconstruct import fit_model, fit_photometric_stereo
from rti_rig.reconstruct.synthetic import fibonacci_lights

P = {"lambert": 3, "hsh1": 4, "ptm": 6, "hsh2": 9, "hsh3": 16}


@settings(max_examples=25, deadline=None)
@given(
    model=st.sampled_from(["hsh1", "ptm", "hsh2", "hsh3"]),
    tile_rows=st.integers(1, 12),
    seed=st.integers(0, 10_000),
)
def test_exactly_determined_fit_interpolates_its_lights(
    model: str, tile_rows: int, seed: int
) -> None:
    """With N = p well-spread lights the fit reproduces every training image (up to rounding)."""
    rng = np.random.default_rng(seed)
    lights = fibonacci_lights(P[model])
    images = rng.uniform(0.2, 1.0, (P[model], 9, 7)).astype(np.float32)
    fitted = fit_model(model, images, lights, tile_rows=tile_rows)
    for i in range(len(lights)):
        np.testing.assert_allclose(fitted.relight(lights[i]), images[i], atol=2e-4)


@settings(max_examples=25, deadline=None)
@given(
    tilt=st.floats(0.0, 30.0),
    azimuth=st.floats(0.0, 360.0),
    albedo=st.floats(0.05, 1.0),
    n_lights=st.integers(3, 20),
    elevation=st.floats(65.0, 85.0),
)
def test_least_squares_ps_recovers_any_unshadowed_normal(
    tilt: float, azimuth: float, albedo: float, n_lights: int, elevation: float
) -> None:
    normal = direction_from_az_el(azimuth, 90.0 - tilt)
    lights = direction_from_az_el(
        np.arange(n_lights) * 360.0 / n_lights + 11.0, np.full(n_lights, elevation)
    )
    images = (albedo * lights @ normal).astype(np.float32)[:, None, None] * np.ones((1, 2, 2))
    for robust in (False, True):
        res = fit_photometric_stereo(images.astype(np.float32), lights, robust=robust)
        assert res.valid.all()
        cos = float(res.normals[0, 0] @ normal)
        assert np.degrees(np.arccos(min(1.0, cos))) < 0.05
        assert abs(float(res.albedo[0, 0]) - albedo) < 1e-4 * max(1.0, albedo) + 1e-5
