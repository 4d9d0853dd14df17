"""The disk check's JPEG allowance holds the worst JPEG a session can write.

It had allowed half a byte a sample ("well under half a byte a sample" at quality 95, 4:4:4),
measured on smooth scenes (a lit relief: 0.06). A noisy or finely textured object's JPEG takes
more: uniform noise 0.81 B a sample, each channel black or white at random 0.97, so the check
before each image let through images the disk could not hold (for a 24 MP camera, 34 MB an
image beyond the check's 8 MB margin). Measured on the files the writer and the CLI write.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.app.disk_estimate import bytes_per_image
from rti_rig.cli import app
from rti_rig.core.image_files import write_srgb_jpeg
from rti_rig.runtime.session import JPEG_BYTES_PER_SAMPLE
from rti_rig.simulator.sim_camera import SimulatedCamera

runner = CliRunner()


def _worst(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    """Each channel of each pixel black or white at random: the largest q95 JPEG found."""
    return (rng.integers(0, 2, (h, w, 3)) * 255).astype(np.uint8)


def _uniform(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    return rng.integers(0, 256, (h, w, 3), dtype=np.uint8)


@pytest.mark.parametrize("picture", [_worst, _uniform])
@pytest.mark.parametrize("size", [(64, 96), (512, 512)])
def test_the_allowance_holds_a_noisy_jpeg(tmp_path: Path, picture, size: tuple[int, int]) -> None:  # type: ignore[no-untyped-def]
    h, w = size
    path = tmp_path / "x.jpg"
    write_srgb_jpeg(path, picture(np.random.default_rng(0), h, w))
    assert path.stat().st_size <= int(h * w * 3 * JPEG_BYTES_PER_SAMPLE) + 16_384


def test_a_session_of_a_noisy_object_stays_within_the_figure_its_disk_check_counts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """simulated_dome's camera looking at the worst texture: every step's files (its TIFF,
    JPEG and record) within the bytes the run's disk checks count for one image."""
    rng = np.random.default_rng(3)
    capture = SimulatedCamera.capture

    def noisy(self: SimulatedCamera, exposure_s: float):  # type: ignore[no-untyped-def]
        frame = capture(self, exposure_s)
        h, w = frame.pixels.shape[:2]
        bits = rng.integers(0, 2, (h, w, 3)).astype(np.uint16) * np.uint16(frame.white_level)
        return dataclasses.replace(frame, pixels=bits.astype(frame.pixels.dtype))

    monkeypatch.setattr(SimulatedCamera, "capture", noisy)
    config = CONFIGS / "simulated_dome.toml"
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(config), "--out", str(out), "--lights", "3", "--no-verdict"])
    assert r.exit_code == 0, said(r)
    bound = bytes_per_image(load_rig_config(config))
    for jpg in sorted(out.glob("image_*.jpg")):
        step = [jpg, *out.glob(f"linear/{jpg.stem}.*"), *out.glob(f"records/{jpg.stem}.*")]
        assert len(step) == 3, step
        written = sum(p.stat().st_size for p in step)
        assert written <= bound, (jpg.name, written, bound)
