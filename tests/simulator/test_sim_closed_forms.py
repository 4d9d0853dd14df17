"""The renderer and camera model against closed forms, at the extremes and for every scene."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rti_rig.core.geometry import direction_from_az_el
from rti_rig.simulator.camera_model import CameraModel, to_srgb8
from rti_rig.simulator.ground_truth import homogeneous_directions, render_ground_truth
from rti_rig.simulator.light_transport import (
    DirectionalLight,
    PointLight,
    light_at,
    render_radiance,
)
from rti_rig.simulator.scenes import (
    SCENE_NAMES,
    Scene,
    make_scene,
    normals_from_height,
    scene_from_depth_file,
    scene_from_normal_file,
)


def plane(height: np.ndarray, albedo: float = 0.5, passes=(), roughness: float = 0.5) -> Scene:  # type: ignore[no-untyped-def]
    h = np.asarray(height, dtype=np.float64)
    shape = h.shape
    return Scene(
        name="test",
        seed=0,
        height=h,
        normals=normals_from_height(h),
        albedo=np.full((*shape, 3), albedo),
        specular_albedo=np.full((*shape, 3), 0.04),
        roughness=np.full(shape, roughness),
        passes=frozenset(passes),
    )


@pytest.mark.parametrize("az", [0.0, 37.0, 145.0, 270.0])
@pytest.mark.parametrize("el", [0.0, 1e-6, 5.0, 30.0, 60.0, 89.9999, 90.0])
def test_lambertian_plane_is_albedo_cos_theta(az: float, el: float) -> None:
    scene = plane(np.zeros((16, 16)), albedo=0.37, passes=("shadows",))
    img = render_radiance(scene, DirectionalLight(tuple(direction_from_az_el(az, el))))
    assert np.all(np.isfinite(img)) and np.all(img >= 0)
    np.testing.assert_allclose(img, 0.37 * np.sin(np.radians(el)), atol=1e-6)


def test_tilted_plane_follows_the_cosine_law() -> None:
    _rows, cols = np.mgrid[0:32, 0:32].astype(np.float64)
    slope = np.tan(np.radians(30.0))
    scene = plane(cols * slope, albedo=0.8)  # rises to the right: normal tilted towards -x
    n = np.array([-np.sin(np.radians(30.0)), 0.0, np.cos(np.radians(30.0))])
    for d in homogeneous_directions(25):
        img = render_radiance(scene, DirectionalLight(tuple(d)))
        np.testing.assert_allclose(img[5:-5, 5:-5], 0.8 * max(float(n @ d), 0.0), atol=1e-5)


@pytest.mark.parametrize("el", [10.0, 20.0, 35.0])
def test_step_edge_casts_a_shadow_of_the_analytic_length(el: float) -> None:
    """A wall of height h lit from +x at elevation e shadows h / tan(e) pixels behind it."""
    h = 12.0
    height = np.zeros((24, 160))
    height[:, 100:] = h  # the raised part is on the light's side (+x = right)
    scene = plane(height, albedo=1.0, passes=("shadows",))
    img = render_radiance(scene, DirectionalLight(tuple(direction_from_az_el(0.0, el))))
    row = img[12, :99, 0]
    lit = np.sin(np.radians(el))
    first_shadowed = int(np.argmax(row < 0.5 * lit))
    expected_start = 100 - h / np.tan(np.radians(el))  # the wall's foot is at column 100
    # within the one-pixel anti-aliasing of the shadow edge (see simulator/shadows.py)
    assert abs(first_shadowed - expected_start) <= 1.5, (first_shadowed, expected_start)
    assert np.all(row[first_shadowed:] < 0.5 * lit)  # dark all the way to the wall
    assert np.all(row[: first_shadowed - 1] == pytest.approx(lit, abs=1e-5))
    flat = render_radiance(scene, DirectionalLight(tuple(direction_from_az_el(0.0, el))), ())
    assert np.sum(flat[12, :98, 0] < 0.5 * lit) == 0  # without the pass, no shadow


def test_point_light_falls_off_as_inverse_square() -> None:
    scene = plane(np.zeros((33, 33)), albedo=0.5)
    near = render_radiance(scene, PointLight((0.0, 0.0, 200.0), power=1.0))
    far = render_radiance(scene, PointLight((0.0, 0.0, 400.0), power=1.0))
    c = (16, 16, 0)
    assert near[c] / far[c] == pytest.approx(4.0, rel=1e-4)
    assert near[c] == pytest.approx(0.5 * 1.0 / 0.2**2, rel=1e-4)  # E = I / r², r in metres
    # Off-centre pixels see the lamp obliquely: cos³ falloff on a plane.
    x = 16 * scene.pixel_size_mm
    r2 = 200.0**2 + x**2
    expected = 0.5 * 1e6 / r2 * (200.0 / np.sqrt(r2))
    assert near[16, 32, 0] == pytest.approx(expected, rel=1e-3)


def test_light_at_makes_point_and_directional_agree_at_the_centre() -> None:
    scene = plane(np.zeros((9, 9)), albedo=0.6)
    d = direction_from_az_el(30.0, 40.0)
    a = render_radiance(scene, light_at(d))
    b = render_radiance(scene, light_at(d, distance_mm=500.0))
    assert b[4, 4, 0] == pytest.approx(a[4, 4, 0], rel=1e-4)


def test_specular_lobe_peaks_at_the_mirror_direction_and_is_skipped_on_matte_scenes() -> None:
    scene = plane(np.zeros((8, 8)), albedo=0.2, passes=("specular",), roughness=0.2)
    peak = render_radiance(scene, DirectionalLight((0.0, 0.0, 1.0)))[4, 4, 0]
    off = render_radiance(scene, DirectionalLight(tuple(direction_from_az_el(0, 45))))[4, 4, 0]
    assert peak > 5 * 0.2 > off / np.sin(np.radians(45)) * 0.9
    matte = render_radiance(scene, DirectionalLight((0.0, 0.0, 1.0)), passes=())
    np.testing.assert_allclose(matte, 0.2, atol=1e-6)


def test_noise_mean_and_variance_match_the_camera_model() -> None:
    cam = CameraModel(full_well_e=20000, read_noise_e=5.0, bit_depth=14, black_level_dn=256)
    radiance = np.full((200, 200), 0.25)
    t = 0.05
    mean_e = 0.25 * cam.electrons_per_unit_s * t
    pixels, white = cam.expose(radiance, t, np.random.default_rng(1))
    k = cam.dn_per_electron
    dn = pixels.astype(np.float64)
    assert dn.mean() == pytest.approx(k * mean_e, rel=0.01)
    expected_var = k**2 * (mean_e + cam.read_noise_e**2) + 1.0 / 12.0  # + quantisation
    assert dn.var() == pytest.approx(expected_var, rel=0.05)
    hot, _ = cam.expose(np.full((10, 10), 1e6), t, np.random.default_rng(2))
    assert np.all(hot == white)  # saturation pins at the white level


def test_camera_outputs_linear_16_bit_and_srgb_8_bit() -> None:
    cam = CameraModel(vignetting=0.3)
    pixels, white = cam.expose(np.full((21, 21), 0.4), 0.05, np.random.default_rng(0))
    assert pixels.dtype == np.uint16 and 0 < white <= 65535
    assert pixels[10, 10] > pixels[0, 0]  # vignetting darkens the corners
    srgb = to_srgb8(pixels, white)
    assert srgb.dtype == np.uint8 and srgb[10, 10] > pixels[10, 10] / white * 255


@pytest.mark.parametrize("name", SCENE_NAMES)
def test_every_library_scene_is_valid_and_reproducible(name: str) -> None:
    a, b = make_scene(name, 40, 48, seed=3), make_scene(name, 40, 48, seed=3)
    np.testing.assert_array_equal(a.height, b.height)
    np.testing.assert_allclose(np.linalg.norm(a.normals, axis=-1), 1.0, atol=1e-9)
    assert np.all((a.albedo >= 0) & (a.albedo <= 1))
    for el in (0.0, 45.0, 90.0):
        img = render_radiance(a, DirectionalLight(tuple(direction_from_az_el(20.0, el))))
        assert np.all(np.isfinite(img)) and np.all(img >= 0)


def test_scenes_declare_only_the_passes_they_need() -> None:
    assert make_scene("flat", 16, 16).passes == frozenset()
    coin = make_scene("coin", 64, 64)
    assert {"shadows", "specular"} <= coin.passes
    flat = make_scene("flat", 32, 32)
    d = DirectionalLight(tuple(direction_from_az_el(10.0, 20.0)))
    np.testing.assert_allclose(
        render_radiance(flat, d), render_radiance(flat, d, ("shadows",)), atol=1e-6
    )


def test_scenes_from_depth_and_normal_files(tmp_path: Path) -> None:
    _rows, cols = np.mgrid[0:20, 0:30].astype(np.float64)
    depth = 3.0 * np.sin(cols / 4.0)
    np.save(tmp_path / "h.npy", depth)
    s = scene_from_depth_file(tmp_path / "h.npy")
    np.testing.assert_allclose(s.normals, normals_from_height(depth), atol=1e-9)
    np.save(tmp_path / "n.npy", s.normals)
    t = scene_from_normal_file(tmp_path / "n.npy")
    np.testing.assert_allclose(t.normals, s.normals, atol=1e-6)


def test_dense_ground_truth() -> None:
    scene = make_scene("tablet", 24, 24, seed=1)
    gt = render_ground_truth(scene, n_lights=60)
    assert gt.images.shape == (60, 24, 24, 3)
    np.testing.assert_allclose(np.linalg.norm(gt.directions, axis=1), 1.0)
    assert np.all(gt.directions[:, 2] > 0) and np.all(np.isfinite(gt.images))
    assert gt.normals is scene.normals
