"""Preview → relief → normals: conversions, light estimate, evidence-fitted scale, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import angle_between_deg, direction_from_az_el
from rti_rig.planner.normals import fit_relief_scale, normals_from_height, sanitize_height
from rti_rig.planner.objectives import cast_shadow_visibility
from rti_rig.planner.topography import (
    PLANNING_SIDE_PX,
    estimate_light,
    given_light,
    linear_luminance,
    planning_image,
    shape_from_shading,
)
from rti_rig.simulator.sim_scene import relief_scene


def sphere_normals(size: int = 96) -> np.ndarray:
    r, c = np.mgrid[0:size, 0:size]
    half = (size - 1) / 2
    x, y = (c - half) / (0.4 * size), (half - r) / (0.4 * size)
    rr = x * x + y * y
    n = np.stack([x, y, np.sqrt(np.clip(1 - rr, 0, None))], axis=-1)
    n[rr >= 1] = (0.0, 0.0, 1.0)
    return n


def test_linear_luminance_conventions() -> None:
    srgb = np.array([[0, 128, 255]], dtype=np.uint8)
    lin = linear_luminance(srgb)
    assert lin[0, 0] == 0.0 and lin[0, 2] == pytest.approx(1.0)
    assert lin[0, 1] == pytest.approx(0.2158, abs=1e-3)  # sRGB 128 is ~21.6 % linear
    assert linear_luminance(np.array([[65535]], dtype=np.uint16))[0, 0] == pytest.approx(1.0)
    rgb = np.zeros((1, 1, 3))
    rgb[0, 0, 1] = 1.0  # pure green, linear float
    assert linear_luminance(rgb)[0, 0] == pytest.approx(0.7152)
    with pytest.raises(ScheduleError, match="NaN"):
        linear_luminance(np.array([[np.nan, 1.0]]))
    with pytest.raises(ScheduleError, match="shape"):
        linear_luminance(np.zeros((2, 2, 2, 2)))
    with pytest.raises(ScheduleError, match="not supported"):
        linear_luminance(np.zeros((2, 2), dtype=np.int32))


def test_planning_image_downsamples_24_megapixels_early() -> None:
    big = np.full((4000, 6000, 3), 200, dtype=np.uint8)
    img = planning_image(big)
    assert max(img.shape) == PLANNING_SIDE_PX and img.shape == (171, 256)
    assert np.allclose(img, linear_luminance(np.full((1, 1, 3), 200, np.uint8))[0, 0])
    assert planning_image(np.ones((1, 1))).shape == (1, 1)


@pytest.mark.parametrize(("az", "el", "tol"), [(30, 45, 20), (200, 60, 15), (0, 90, 1)])
def test_light_estimate_on_a_sphere(az: float, el: float, tol: float) -> None:
    light = direction_from_az_el(az, el)
    image = np.clip(sphere_normals() @ light, 0, None)
    est = estimate_light(image)
    assert float(angle_between_deg(est.direction, light)) < tol
    if el < 90:
        assert est.source == "estimated" and est.why_zenith is None


def test_light_estimate_degenerate_images_give_zenith() -> None:
    """Said assumed, with why: the zenith had been reported as "estimated"."""
    for img in (np.zeros((8, 8)), np.ones((8, 8)), np.ones((1, 1))):
        est = estimate_light(img)
        assert np.allclose(est.direction, (0, 0, 1))
        assert est.source == "assumed" and est.why_zenith, est


def test_given_light_is_validated() -> None:
    assert np.allclose(given_light((0.0, 90.0)), (0, 0, 1), atol=1e-12)
    with pytest.raises(ScheduleError, match="elevation"):
        given_light((10.0, 0.0))


@pytest.mark.parametrize(("az", "el"), [(30, 45), (0, 90), (200, 25)])
def test_relief_scale_is_recovered_from_shading(az: float, el: float) -> None:
    """The true relief scaled by 0.1: the fit must find ~10 (and the convex sign)."""
    scene = relief_scene(96, 96, seed=1)
    light = direction_from_az_el(az, el)
    image = 0.7 * np.clip(scene.normals @ light, 0, None)
    fit = fit_relief_scale(scene.height * 0.1, image, light)
    assert fit.scale == pytest.approx(10.0, rel=0.08)
    assert fit.albedo == pytest.approx(0.7, rel=0.05)
    assert fit.explained > 0.99


def test_flat_relief_has_zero_scale_and_zenith_normals() -> None:
    fit = fit_relief_scale(np.zeros((10, 10)), np.full((10, 10), 0.5), np.array([0, 0, 1.0]))
    assert fit.scale == 0.0 and fit.rms_slope_deg == 0.0
    assert np.allclose(normals_from_height(np.zeros((3, 3))), (0, 0, 1))


@pytest.mark.parametrize(("az", "el"), [(30, 45), (0, 90)])
def test_shape_from_shading_beats_assuming_flat(az: float, el: float) -> None:
    scene = relief_scene(96, 96, seed=2)
    light = direction_from_az_el(az, el)
    image = np.clip(scene.normals @ light, 0, None)
    relief = shape_from_shading(image, light)
    fit = fit_relief_scale(relief, image, light)
    normals = normals_from_height(fit.scale * relief)
    err = float(np.mean(angle_between_deg(normals, scene.normals)))
    flat = float(np.mean(angle_between_deg(np.array([0, 0, 1.0]), scene.normals)))
    assert np.all(np.isfinite(normals))
    assert err < flat


def test_shape_from_shading_tiny_and_black_images() -> None:
    light = direction_from_az_el(10, 40)
    assert shape_from_shading(np.ones((1, 1)), light).shape == (1, 1)
    assert np.all(shape_from_shading(np.zeros((5, 5)), light) == 0)


def test_nonfinite_relief_is_repaired_or_refused() -> None:
    h = np.arange(16.0).reshape(4, 4)
    h[0, 0], h[1, 1] = np.nan, np.inf
    fixed, bad = sanitize_height(h, "model.onnx")
    assert bad == 2 and np.all(np.isfinite(fixed))
    with pytest.raises(ScheduleError, match=r"model\.onnx: 16 of 16 .*NaN or infinite"):
        sanitize_height(np.full((4, 4), np.nan), "model.onnx")


def test_cast_shadow_from_a_wall() -> None:
    """A wall east of a pixel shadows a low light from the east, not one from the west."""
    height = np.zeros((20, 20))
    height[:, 12:] = 10.0
    rows, cols = np.array([10]), np.array([8])
    east, west = direction_from_az_el(0, 20), direction_from_az_el(180, 20)
    high_east = direction_from_az_el(0, 80)
    vis = cast_shadow_visibility(height, rows, cols, np.stack([east, west, high_east]))
    assert vis.tolist() == [[0.0, 1.0, 1.0]]


def test_read_preview_keeps_type_and_rgb_order(tmp_path) -> None:
    import cv2

    from rti_rig.planner.topography import read_preview

    rgb = np.zeros((4, 5, 3), np.uint8)
    rgb[..., 0] = 200  # red
    cv2.imwrite(str(tmp_path / "p.png"), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
    got = read_preview(tmp_path / "p.png")
    assert got.dtype == np.uint8 and got.shape == (4, 5, 3) and got[0, 0, 0] == 200
    deep = np.full((3, 3), 40000, np.uint16)
    cv2.imwrite(str(tmp_path / "d.tif"), deep)
    assert read_preview(tmp_path / "d.tif").dtype == np.uint16
    with pytest.raises(ScheduleError, match="not found"):
        read_preview(tmp_path / "none.jpg")
    (tmp_path / "bad.jpg").write_bytes(b"xx")
    with pytest.raises(ScheduleError, match="cannot read"):
        read_preview(tmp_path / "bad.jpg")
