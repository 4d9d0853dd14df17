"""Scene library: shapes, ground truth consistency, determinism, passes, loading from files."""

import cv2
import numpy as np
import pytest

from rti_rig.simulator.scenes import (
    SCENE_NAMES,
    SceneError,
    height_from_normals,
    make_scene,
    normals_from_height,
    scene_from_depth_file,
    scene_from_normal_file,
)

#: the calibration sphere's normals are analytic (its truth), not differenced: tested apart
DIFFERENCED = [n for n in SCENE_NAMES if n != "sphere"]


@pytest.mark.parametrize("name", DIFFERENCED)
def test_scene_ground_truth_is_consistent(name):
    s = make_scene(name, 40, 56, seed=2)
    assert s.height.shape == (40, 56) and s.normals.shape == (40, 56, 3)
    np.testing.assert_allclose(np.linalg.norm(s.normals, axis=-1), 1.0, atol=1e-12)
    np.testing.assert_allclose(s.normals, normals_from_height(s.height))
    assert s.albedo.min() >= 0 and s.albedo.max() <= 1
    assert s.normals[..., 2].min() > 0
    assert s.passes <= {"shadows", "specular"}
    with pytest.raises(ValueError):
        s.height[0, 0] = 1.0  # read-only ground truth


@pytest.mark.parametrize("name", [n for n in SCENE_NAMES if n not in ("flat", "sphere")])
def test_scenes_are_seeded(name):
    a, b = make_scene(name, 32, 32, seed=1), make_scene(name, 32, 32, seed=1)
    c = make_scene(name, 32, 32, seed=2)
    np.testing.assert_array_equal(a.height, b.height)
    assert not np.array_equal(a.height, c.height)


def test_passes_say_what_each_scene_needs():
    passes = {n: make_scene(n, 16, 16).passes for n in SCENE_NAMES}
    assert passes["flat"] == frozenset()
    assert passes["tablet"] == {"shadows"} and passes["tilted"] == {"shadows"}
    assert passes["coin"] == {"shadows", "specular"}
    assert "specular" in passes["industrial"]
    assert make_scene("tablet", 16, 16).specular_albedo.max() == 0


def test_tilted_scene_is_strongly_tilted():
    s = make_scene("tilted", 64, 64)
    tilt = np.degrees(np.arccos(s.normals[..., 2]))
    assert np.median(tilt) > 35


def test_unknown_scene_names_choices():
    with pytest.raises(SceneError, match="coin"):
        make_scene("statue", 16, 16)


def test_normals_from_height_frame():
    rows = np.arange(10)[:, None] * np.ones((1, 12))
    n = normals_from_height(2.0 * rows)  # higher towards the bottom rows (y down)
    np.testing.assert_allclose(n[5, 5], np.array([0, 2, 1]) / np.sqrt(5), atol=1e-12)


def test_height_from_normals_recovers_smooth_surface():
    u, v = np.meshgrid(np.linspace(-1, 1, 64), np.linspace(-1, 1, 48))
    h = 6 * np.exp(-(u**2 + v**2) * 3)
    rec = height_from_normals(normals_from_height(h))
    err = (rec - rec.mean()) - (h - h.mean())
    assert np.abs(err).max() < 0.05 * np.ptp(h)


def test_scene_from_depth_file_png_and_npy(tmp_path):
    h = (np.arange(20)[None, :] * np.ones((16, 1)) * 1000).astype(np.uint16)
    cv2.imwrite(str(tmp_path / "d.png"), h)
    s = scene_from_depth_file(tmp_path / "d.png", relief_px=19.0)
    np.testing.assert_allclose(s.height[0, :3], [0, 1, 2])
    assert s.normals[5, 5, 0] < 0  # rising to the right: normal leans left
    np.save(tmp_path / "d.npy", h.astype(float))
    s2 = scene_from_depth_file(tmp_path / "d.npy", scale_px=0.001, is_depth=True)
    np.testing.assert_allclose(s2.height[0, 1], -1.0)
    with pytest.raises(SceneError, match="no such file"):
        scene_from_depth_file(tmp_path / "missing.png")


def test_scene_from_normal_file_roundtrip(tmp_path):
    u, v = np.meshgrid(np.linspace(-1, 1, 32), np.linspace(-1, 1, 32))
    n = normals_from_height(4 * np.exp(-(u**2 + v**2) * 2))
    rgb = np.rint((n + 1) / 2 * 65535).astype(np.uint16)
    cv2.imwrite(str(tmp_path / "n.png"), rgb[..., ::-1])  # OpenCV writes BGR
    s = scene_from_normal_file(tmp_path / "n.png")
    np.testing.assert_allclose(s.normals, n, atol=1e-3)
    flipped = scene_from_normal_file(tmp_path / "n.png", green_up=False)
    np.testing.assert_allclose(flipped.normals[..., 1], -n[..., 1], atol=1e-3)
    assert s.passes == frozenset()


def test_sphere_normals_are_the_spheres_and_its_circle_is_where_it_is():
    """The sphere scene's normals point out of a sphere centred on its circle (y up, rows
    down), and its height agrees with them away from the rim, where differencing is fair."""
    from rti_rig.simulator.scenes import sphere_circle

    s = make_scene("sphere", 60, 80)
    cx, cy, r = sphere_circle(60, 80)
    assert s.metadata["sphere_circle_px"] == (cx, cy, r)
    rows, cols = np.mgrid[0:60, 0:80]
    inside = np.hypot(cols - cx, rows - cy) < 0.7 * r
    np.testing.assert_allclose(s.normals[..., 0][inside], ((cols - cx) / r)[inside], atol=1e-12)
    np.testing.assert_allclose(s.normals[..., 1][inside], ((cy - rows) / r)[inside], atol=1e-12)
    differenced = normals_from_height(s.height)
    cosines = (differenced * s.normals).sum(-1)[inside]
    assert np.degrees(np.arccos(np.clip(cosines.min(), -1, 1))) < 3.0
    assert s.normals[..., 2].min() >= 0 and s.passes == {"specular"}
