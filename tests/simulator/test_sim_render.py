"""Closed-form checks of the renderer: Lambert plane, grazing/zenith, shadow length, 1/r², GGX."""

import math

import numpy as np
import pytest

from rti_rig.core.geometry import direction_from_az_el
from rti_rig.simulator.ground_truth import homogeneous_directions, render_ground_truth
from rti_rig.simulator.light_transport import (
    DirectionalLight,
    PointLight,
    light_at,
    render_radiance,
)
from rti_rig.simulator.scenes import SCENE_NAMES, Scene, make_scene, normals_from_height
from rti_rig.simulator.shadows import directional_visibility, point_visibility


def _plane_scene(height, albedo=0.5, spec=0.0, rough=1.0, passes=()):
    h = np.asarray(height, dtype=np.float64)
    shape = h.shape
    return Scene(
        name="test",
        seed=0,
        height=h,
        normals=normals_from_height(h),
        albedo=np.full((*shape, 3), albedo),
        specular_albedo=np.full((*shape, 3), spec),
        roughness=np.full(shape, rough),
        passes=frozenset(passes),
    )


@pytest.mark.parametrize("el", [0.0, 1e-4, 5.0, 30.0, 60.0, 89.999, 90.0])
@pytest.mark.parametrize("az", [0.0, 77.0, 200.0])
def test_lambert_plane_is_albedo_cos(az, el):
    scene = make_scene("flat", 16, 16)
    img = render_radiance(scene, DirectionalLight(tuple(direction_from_az_el(az, el))))
    expected = 0.5 * math.sin(math.radians(el))
    assert np.all(np.isfinite(img)) and img.min() >= 0
    np.testing.assert_allclose(img, expected, atol=1e-6)


def test_tilted_plane_follows_cosine_between_normal_and_light():
    rows = np.arange(32)[:, None] * np.ones((1, 32))
    scene = _plane_scene(0.5 * (31 - rows))  # rises towards the top: normal tilts to -y
    n = scene.normals[10, 10]
    assert n[1] < 0 and abs(n[0]) < 1e-12
    for az, el in [(90, 30), (270, 30), (0, 45)]:
        d = direction_from_az_el(az, el)
        img = render_radiance(scene, DirectionalLight(tuple(d)))
        np.testing.assert_allclose(img[10, 10], 0.5 * max(0.0, float(n @ d)), atol=1e-6)


@pytest.mark.parametrize("name", SCENE_NAMES)
def test_every_scene_finite_and_non_negative_at_grazing_and_zenith(name):
    scene = make_scene(name, 48, 64, seed=3)
    for az, el in [(0, 0.0), (33, 1e-3), (180, 90.0), (10, -5.0), (250, 89.99)]:
        for dist in (None, 300.0):
            img = render_radiance(scene, light_at(direction_from_az_el(az, el), dist))
            assert img.shape == (48, 64, 3)
            assert np.all(np.isfinite(img)) and img.min() >= 0, (name, az, el, dist)


@pytest.mark.parametrize("el", [10.0, 30.0, 45.0, 70.0])
def test_step_edge_shadow_has_analytic_length(el):
    h = np.zeros((60, 300))
    h[:, :100] = 20.0  # high on the left; light from the left (azimuth 180°)
    vis = directional_visibility(h, direction_from_az_el(180.0, el))
    length = 20.0 / math.tan(math.radians(el))
    measured = int((vis[30, 100:] < 0.5).sum())
    assert abs(measured - length) <= 1.0 + 1e-9  # one pixel of discretisation
    assert np.all(vis[:, :100] > 0.99)


def test_oblique_step_edge_shadow_length():
    rows, cols = 200, 200
    x = np.arange(cols)[None, :] - (cols - 1) / 2
    y = (rows - 1) / 2 - np.arange(rows)[:, None]
    az, el, wall = 30.0, 35.0, 15.0
    a = math.radians(az)
    s = x * math.cos(a) + y * math.sin(a)  # distance along the azimuth, towards the light
    vis = directional_visibility(np.where(s > 0, wall, 0.0), direction_from_az_el(az, el))
    length = wall / math.tan(math.radians(el))
    low = (s <= 0) & (np.abs(x) < 60) & (np.abs(y) < 60)  # occluders inside the image
    assert np.all(vis[low & (-s < length - 1.5)] < 0.5)
    assert np.all(vis[low & (-s > length + 1.5)] > 0.5)


def test_point_light_shadow_is_exact_for_finite_distance():
    h = np.zeros((40, 300))
    h[:, :100] = 20.0  # wall top at col 99
    for col, z in [(50.0, 100.0), (-300.0, 100.0)]:
        vis = point_visibility(h, col, 20.0, z)
        length = 20.0 * (99.0 - col) / (z - 20.0)
        # Polar resampling places the occluding top within half a sample: 1.5 px tolerance.
        assert abs(int((vis[20, 100:] < 0.5).sum()) - length) <= 1.5


def test_point_light_falls_off_as_inverse_square():
    scene = make_scene("flat", 9, 9, pixel_size_mm=0.1)
    c = scene.normals.shape[0] // 2
    vals = [render_radiance(scene, PointLight((0.0, 0.0, r), 2.0))[c, c, 0] for r in (250, 500)]
    np.testing.assert_allclose(vals[0] / vals[1], 4.0, rtol=1e-4)
    np.testing.assert_allclose(vals[1], 0.5 * 2.0 / 0.5**2, rtol=1e-4)
    # Off-centre pixel: E·cos θ = I·z / r³.
    img = render_radiance(scene, PointLight((0.3, 0.0, 1.0), 1.0))
    x_mm = (8 - 4) * 0.1  # column 8, four pixels right of centre
    r = math.hypot(0.3 - x_mm, 1.0)
    np.testing.assert_allclose(img[c, 8, 0], 0.5 * 1e6 * 1.0 / r**3, rtol=1e-4)


def test_light_at_point_matches_directional_at_centre():
    scene = make_scene("flat", 9, 9)
    d = direction_from_az_el(40, 50)
    a = render_radiance(scene, light_at(d))[4, 4]
    b = render_radiance(scene, light_at(d, 400.0))[4, 4]
    np.testing.assert_allclose(a, b, rtol=1e-5)


def test_ggx_peak_matches_closed_form_at_normal_incidence():
    scene = _plane_scene(np.zeros((8, 8)), albedo=0.0, spec=0.04, rough=0.5, passes={"specular"})
    img = render_radiance(scene, DirectionalLight((0.0, 0.0, 1.0)))
    alpha = 0.5**2
    # π·D = 1/α², G/(4 n·l n·v) = 1/4, F = F0 at normal incidence.
    np.testing.assert_allclose(img, 0.04 / (4 * alpha**2), rtol=1e-5)
    off = render_radiance(scene, DirectionalLight(tuple(direction_from_az_el(0, 40))))
    assert off.max() < img.min()


def test_passes_not_needed_are_skipped(monkeypatch):
    import rti_rig.simulator.light_transport as lt

    def boom(*_a, **_k):
        raise AssertionError("pass should have been skipped")

    monkeypatch.setattr(lt, "directional_visibility", boom)
    monkeypatch.setattr(lt, "specular_term", boom)
    flat = make_scene("flat", 16, 16)
    render_radiance(flat, DirectionalLight((0.3, 0.2, 0.9)))
    tablet = make_scene("tablet", 32, 32)
    with pytest.raises(AssertionError):
        render_radiance(tablet, DirectionalLight((0.3, 0.2, 0.9)))


def test_row_order_bump_lit_from_top_is_brighter_on_top():
    u, v = np.meshgrid(np.arange(41) - 20.0, 20.0 - np.arange(41))
    scene = _plane_scene(8 * np.exp(-(u**2 + v**2) / 60.0))
    img = render_radiance(scene, DirectionalLight(tuple(direction_from_az_el(90, 30))))
    assert img[14, 20, 0] > img[26, 20, 0]  # row 14 is above the centre (y up)


def test_homogeneous_directions_and_ground_truth():
    d = homogeneous_directions(500)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0)
    assert d[:, 2].min() > 0 and abs(d[:, 2].mean() - 0.5) < 1e-9  # equal area in z
    assert abs(d[:, 0].mean()) < 0.01 and abs(d[:, 1].mean()) < 0.01
    gt = render_ground_truth(make_scene("flat", 8, 8), n_lights=50)
    assert gt.images.shape == (50, 8, 8, 3)
    np.testing.assert_allclose(gt.images[:, 0, 0, 0], 0.5 * gt.directions[:, 2], atol=1e-6)
