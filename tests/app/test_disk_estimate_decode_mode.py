"""A RAW camera's per-image disk bound follows its decode mode and the files it keeps.

Every RAW camera had been allowed 7.5 bytes a pixel (a full-size 16-bit RGB TIFF and its JPEG)
whatever ``[camera.device.decode] mode`` was: about twice what a ``"half"`` or ``"mosaic"``
session writes (disks that held the session were refused), and in ``"demosaic"`` mode the RAW
the session keeps in ``raw/`` was not counted (a disk too small was let through, to fill
mid-session). Measured here on the files the session really writes: a Bayer scene through a
DNG (the simulated DSLR's path), decoded in each mode by the real decode, written as the
session writes it.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import linear_to_srgb8, write_linear_tiff, write_srgb_jpeg
from rti_rig.drivers.cameras.raw_roundtrip import encode_decode
from rti_rig.drivers.cameras.settings import RawDecodeSettings
from rti_rig.runtime.session import estimated_bytes_per_image

W, H = 600, 400  # a sensor big enough that the files' headers do not matter


def _scene() -> np.ndarray:
    """A lit object's shading (smooth, with a little noise), in units of full scale."""
    y, x = np.mgrid[0:H, 0:W] / max(H, W)
    shade = 0.2 + 0.6 * np.clip(np.cos(3 * (x - 0.5)) * np.cos(3 * (y - 0.4)), 0, 1)
    rng = np.random.default_rng(7)
    rgb = shade[..., None] * np.array([0.9, 0.7, 0.5]) + rng.normal(0, 0.01, (H, W, 3))
    return np.clip(rgb, 0, 1)


def _written(tmp_path: Path, mode: str) -> tuple[int, int]:
    """Bytes the session keeps for one step in ``mode`` (the DNG, the TIFF, our JPEG), and
    the bytes of a full-size camera JPEG (q95 4:4:4, as ours: a camera's fine JPEG)."""
    dng = tmp_path / f"{mode}.dng"
    frame = encode_decode(_scene(), 0.1, RawDecodeSettings(mode=mode), path=dng)
    tif, jpg = tmp_path / f"{mode}.tif", tmp_path / f"{mode}.jpg"
    write_linear_tiff(tif, frame.pixels)
    write_srgb_jpeg(jpg, linear_to_srgb8(frame.pixels, frame.white_level))
    camera_jpg = tmp_path / f"{mode}_camera.jpg"
    full = (_scene() * 65535).astype(np.uint16)
    write_srgb_jpeg(camera_jpg, linear_to_srgb8(full, 65535))
    kept = sum(p.stat().st_size for p in (dng, tif, jpg))
    return kept, camera_jpg.stat().st_size


@pytest.mark.parametrize("mode", ["demosaic", "half", "mosaic"])
def test_the_bound_holds_what_each_mode_writes_and_not_twice_that(
    tmp_path: Path, mode: str
) -> None:
    kept, camera_jpeg = _written(tmp_path, mode)
    bound = estimated_bytes_per_image(W, H, mode, kept_raw=True)
    # within half as much again: the JPEG's allowance is the worst JPEG's (a noisy object's,
    # tests/app/test_jpeg_allowance.py), this smooth scene's is a tenth of it
    assert kept <= bound <= 1.5 * kept, (mode, kept, bound)
    with_jpeg = estimated_bytes_per_image(W, H, mode, kept_raw=True, kept_jpeg=True)
    # the JPEGs' bound is the worst JPEG's (a byte a sample): only that it is counted, in full
    assert kept + camera_jpeg <= with_jpeg and with_jpeg - bound >= 3 * W * H // 2, with_jpeg


def test_a_camera_that_delivers_frames_keeps_the_full_size_rgb_bound() -> None:
    """An opencv camera or a simulated one: no RAW kept, its frames full-size RGB."""
    assert estimated_bytes_per_image(W, H) == estimated_bytes_per_image(W, H, "demosaic")
    assert estimated_bytes_per_image(W, H) < estimated_bytes_per_image(W, H, kept_raw=True)


runner = CliRunner()


def _rig_config(tmp_path: Path, mode: str) -> Path:
    """The shipped gphoto2 dome (6000 × 4000) in ``mode``, its port a path that is no device
    (nothing real is opened: an accepted run stops at the port)."""
    text = (CONFIGS / "example_dome_48.toml").read_text()
    text = text.replace('mode = "demosaic"', f'mode = "{mode}"')
    text = text.replace(
        'port = "/dev/serial/by-id/usb-Arduino_Mega_2560-if00"',
        f'port = "{tmp_path / "no-such-port"}"',
    )
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp_path)  # its LED positions, beside it
    path = tmp_path / f"dome_{mode}.toml"
    path.write_text(text)
    return path


def test_a_half_size_session_fits_where_a_demosaiced_one_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """48 images of a 24 MP RAW camera: room for the half-size session (each step its DNG,
    its half-size TIFF and JPEG) but not for the demosaiced one. The half-size run had been
    refused as if it wrote full-size RGB."""
    lights = 48
    half = estimated_bytes_per_image(6000, 4000, "half", kept_raw=True)
    free = lights * half + 8 * 1024 * 1024 + 1_000_000
    assert free < lights * estimated_bytes_per_image(6000, 4000)  # the old bound refused it
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage._replace(free=free))
    said_by = {}
    for mode in ("half", "demosaic"):
        out = tmp_path / f"s_{mode}"
        config = _rig_config(tmp_path, mode)
        r = runner.invoke(app, ["run", str(config), "--out", str(out), "--no-verdict"])
        said_by[mode] = said(r)
        assert r.exit_code != 0 and "Traceback" not in said(r), said(r)
    assert "not enough free disk space" not in said_by["half"], said_by["half"]
    assert "no-such-port" in said_by["half"], said_by["half"]  # it went on to the dome
    assert f"not enough free disk space for {lights} image(s)" in said_by["demosaic"]


def test_the_controller_counts_the_bytes_the_composition_root_gives(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The check before each image counts the rig's own figure (a RAW camera's, by its decode
    mode), as the start-up check does: it had counted full-size RGB for every camera."""
    from rti_rig.app.compose import build_rig
    from rti_rig.app.config import load_rig_config
    from rti_rig.app.disk_estimate import bytes_per_image
    from rti_rig.planner.uniform import plan_uniform
    from rti_rig.runtime.controller import run_session
    from rti_rig.runtime.session import NoSpaceError, SessionFolder

    loaded = load_rig_config(CONFIGS / "simulated_dome.toml")
    rig = build_rig(loaded)
    assert rig.bytes_per_image == bytes_per_image(loaded)
    rig.bytes_per_image = 100 * estimated_bytes_per_image(512, 512)  # as a huge RAW would be
    usage = shutil.disk_usage(tmp_path)
    free = 2 * estimated_bytes_per_image(512, 512) + 8 * 1024 * 1024 + 1_000_000
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage._replace(free=free))
    schedule = plan_uniform(rig.geometry, 2)
    with rig, pytest.raises(NoSpaceError, match="for 2 image"):
        run_session(rig, schedule, SessionFolder.create(tmp_path / "s", 2))
