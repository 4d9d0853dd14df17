"""Camera model: Poisson–Gaussian statistics, saturation, bit depth, vignetting, sRGB export."""

import cv2
import numpy as np
import pytest

from rti_rig.simulator.camera_model import CameraModel, encode_jpeg, to_srgb8


def test_noise_mean_and_variance_match_model():
    cam = CameraModel(
        full_well_e=20000,
        read_noise_e=5.0,
        bit_depth=16,
        gain=2.0,
        black_level_dn=1024,
        electrons_per_unit_s=1e5,
    )
    rad = np.full((400, 500), 0.3)
    px, white = cam.expose(rad, 0.1, np.random.default_rng(1))
    k = 2.0 * (65535 - 1024) / 20000
    phi = 0.3 * 1e5 * 0.1  # 3000 e
    mean, var = k * phi, k * k * (phi + 25.0) + 1 / 12
    x = px.astype(float)
    assert abs(x.mean() - mean) < 4 * np.sqrt(var / x.size)
    assert abs(x.var() / var - 1) < 0.02  # 200k samples: σ of the ratio ≈ 0.3 %
    assert white == 65535 - 1024


def test_shot_noise_dominates_proportionally():
    cam = CameraModel(read_noise_e=0.0)
    rng = np.random.default_rng(0)
    lo, _ = cam.expose(np.full((300, 300), 0.01), 0.1, rng)
    hi, _ = cam.expose(np.full((300, 300), 0.04), 0.1, rng)
    ratio = hi.astype(float).var() / lo.astype(float).var()
    assert 3.7 < ratio < 4.3  # Poisson: variance ∝ mean


def test_saturation_and_bit_depth():
    cam = CameraModel(bit_depth=12, black_level_dn=64)
    px, white = cam.expose(np.full((10, 10, 3), 50.0), 1.0, np.random.default_rng(0))
    assert white == 4095 - 64 and px.dtype == np.uint16
    assert np.all(px == white)
    low_gain = CameraModel(gain=0.5)
    px2, white2 = low_gain.expose(np.full((4, 4), 50.0), 1.0, np.random.default_rng(0))
    assert white2 == round(0.5 * (16383 - 512)) and np.all(px2 == white2)


def test_dark_frame_has_no_negative_and_is_near_zero():
    px, _ = CameraModel().expose(np.zeros((100, 100)), 0.01, np.random.default_rng(0))
    assert px.max() < 20 and px.mean() < 3


def test_vignetting_darkens_corners_by_strength():
    cam = CameraModel(vignetting=0.4, read_noise_e=0.0)
    phi = cam.expected_electrons(np.ones((51, 51)), 0.01)
    assert phi[25, 25] == pytest.approx(2000.0)
    assert phi[0, 0] == pytest.approx(2000.0 * 0.6)


def test_expose_validates_inputs():
    cam = CameraModel()
    with pytest.raises(ValueError, match="exposure_s"):
        cam.expose(np.ones((4, 4)), 0.0, np.random.default_rng(0))
    with pytest.raises(ValueError, match="radiance"):
        cam.expose(np.full((4, 4), np.nan), 0.1, np.random.default_rng(0))
    with pytest.raises(ValueError, match="bit_depth"):
        CameraModel(bit_depth=20)


def test_exposure_for_targets_fraction_of_white():
    cam = CameraModel(read_noise_e=0.0)
    t = cam.exposure_for(0.5, 0.5)
    px, white = cam.expose(np.full((200, 200), 0.5), t, np.random.default_rng(0))
    assert abs(px.mean() / white - 0.5) < 0.005


def test_srgb8_and_jpeg():
    out = to_srgb8(np.array([0, 1000, 2000, 4000]), 2000)
    assert out.tolist() == [0, 188, 255, 255]  # sRGB(0.5) = 0.7354 -> 188
    img = to_srgb8(np.full((8, 8, 3), 500), 1000)
    data = encode_jpeg(img)
    dec = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    assert dec.shape == (8, 8, 3) and abs(int(dec.mean()) - 188) <= 2
