"""A dome session on a tiny simulated rig whose camera delivers RAW-like data (DNG → rawpy).

Shows that the simulated sensor data survives the real decode path linearly: photometric
stereo on the decoded frames recovers the sphere's normals.
"""

from __future__ import annotations

import json

import numpy as np

from rti_rig.core.clock import VirtualClock
from rti_rig.core.devices import Camera, DiscreteLightSource
from rti_rig.drivers.cameras.exposure import meter_exposure
from rti_rig.drivers.cameras.raw_decode import decode_raw
from rti_rig.drivers.cameras.raw_roundtrip import RawRoundTripCamera
from rti_rig.drivers.cameras.settings import ExposureRule, RawDecodeSettings

SIZE = 64
ALBEDO = np.array([0.8, 0.6, 0.4])


def light_directions() -> np.ndarray:
    dirs = []
    for elev, n in ((30.0, 6), (55.0, 5), (80.0, 1)):
        for k in range(n):
            az = np.deg2rad(360.0 * k / n + 15.0 * (elev == 55.0))
            e = np.deg2rad(elev)
            dirs.append([np.cos(e) * np.cos(az), np.cos(e) * np.sin(az), np.sin(e)])
    return np.array(dirs)


def sphere_normals() -> tuple[np.ndarray, np.ndarray]:
    # object frame: x right, y up (image rows run down), z towards the camera
    c = (SIZE - 1) / 2
    yy, xx = np.mgrid[0:SIZE, 0:SIZE]
    x, y = (xx - c) / 28.0, (c - yy) / 28.0
    r2 = x**2 + y**2
    inside = r2 < 1.0
    z = np.sqrt(np.clip(1.0 - r2, 0.0, None))
    return np.stack([x, y, z], axis=-1) * inside[..., None], inside


class SimDome:
    """Just enough of a dome: one light on at a time."""

    name = "sim-dome"

    def __init__(self, dirs: np.ndarray) -> None:
        self.dirs, self.on = dirs, None

    def connect(self) -> None: ...

    def close(self) -> None:
        self.all_off()

    def light_count(self) -> int:
        return len(self.dirs)

    def light(self, index: int, intensity: float = 1.0) -> None:
        self.on = index

    def all_off(self) -> None:
        self.on = None


def test_session_raw_like_frames_recover_normals(tmp_path):
    dirs = light_directions()
    normals, inside = sphere_normals()
    dome = SimDome(dirs)
    rng = np.random.default_rng(11)
    irradiance = 3.0  # full scale per second for a white, frontally lit surface

    def render(exposure_s: float) -> np.ndarray:
        if dome.on is None:
            shade = np.zeros((SIZE, SIZE))
        else:
            shade = np.clip(normals @ dome.dirs[dome.on], 0.0, None)
        signal = shade[..., None] * ALBEDO * irradiance * exposure_s
        return signal + rng.normal(0.0, 2e-4, signal.shape)  # read noise

    raw_dir = tmp_path / "raw"
    cam = RawRoundTripCamera(
        "sim-camera",
        render,
        RawDecodeSettings(mode="mosaic"),
        output_dir=raw_dir,
        clock=VirtualClock(),
    )
    assert isinstance(cam, Camera) and isinstance(dome, DiscreteLightSource)
    cam.connect()
    dome.connect()
    try:
        # exposure: metered at the brightest planned light (the highest one here)
        dome.light(int(np.argmax(dirs[:, 2])))
        choice = meter_exposure(cam, ExposureRule(max_saturated_fraction=0.001), 1.0)
        assert choice.satisfied
        # near the noise-free optimum (brightest pixel 0.8 × 3/s × t reaches white at 0.417 s):
        # read noise makes the first prediction fail verification; backing off recovers
        assert 0.33 < choice.exposure_s < 0.417
        frames = []
        for i in range(len(dirs)):
            dome.light(i)
            frames.append(cam.capture(choice.exposure_s))
    finally:
        dome.close()
        cam.close()
    assert dome.on is None
    manifest = {"exposure": choice.to_manifest(), "frames": [f.metadata for f in frames]}
    json.dumps(manifest)
    assert manifest["exposure"]["exposure_s"] == choice.exposure_s
    files = sorted(raw_dir.glob("cap*.dng"))
    assert len(files) == len(choice.test_exposures_s) + len(dirs)
    # the files on disk decode to the same data the session used
    again = decode_raw(files[-1], RawDecodeSettings(mode="mosaic"))
    np.testing.assert_array_equal(again.pixels, frames[-1].pixels)
    assert max(f.saturated_fraction for f in frames) <= 0.001

    # Lambertian photometric stereo per photosite on the decoded linear data
    stack = np.stack([f.pixels.astype(np.float64) / f.white_level for f in frames], axis=-1)
    lit = np.all((normals @ dirs.T) > 0.1, axis=-1) & inside
    lit &= np.all(stack < 1.0, axis=-1)
    obs = stack[lit]  # (n_pixels, n_lights)
    g, *_ = np.linalg.lstsq(dirs, obs.T, rcond=None)
    est = (g / np.linalg.norm(g, axis=0)).T
    cos = np.clip(np.sum(est * normals[lit], axis=-1), -1.0, 1.0)
    err_deg = np.rad2deg(np.arccos(cos))
    assert lit.sum() > 400
    assert np.median(err_deg) < 0.5
    assert np.percentile(err_deg, 99) < 3.0
