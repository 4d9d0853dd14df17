"""A clipped preview is said by ``rti-rig plan``, through the front door.

Found by a sweep of 12-bit acquisitions: the shipped dome's zenith image at three times its
exposure, 89 % of its pixels clipped (at 65535, or at 4095 as a 12-bit camera stores it), was
planned from without a word, the relief read from its shading flat wherever it clipped.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import tifffile
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.app.preview_clipping import PREVIEW_CLIPPED_LIMIT
from rti_rig.cli import app
from rti_rig.core.image_files import linear_to_srgb8, read_linear_tiff

runner = CliRunner()


def _plan(preview: Path, out: Path) -> str:
    r = runner.invoke(
        app,
        [
            "plan",
            str(preview),
            "--rig",
            str(CONFIGS / "simulated_dome.toml"),
            "--method",
            "optimal",
            "--lights",
            "9",
            "--out",
            str(out),
        ],
    )
    assert r.exit_code == 0, r.output
    return said(r)


def _zenith(session: Path) -> np.ndarray:
    """The session's brightest image (its zenith light), as linear values 0..1."""
    images = [read_linear_tiff(p) for p in sorted((session / "linear").glob("*.tif"))]
    return max(images, key=lambda a: float(a.mean())).astype(np.float64) / 65535


def test_a_clipped_preview_is_said_at_its_clip_level(dome_relief: Path, tmp_path: Path) -> None:
    lit = _zenith(dome_relief)
    assert lit.max() < 1.0  # as shot, nothing clips: no note
    as_shot = tmp_path / "as_shot.tif"
    tifffile.imwrite(as_shot, np.round(lit * 65535).astype(np.uint16))
    assert "of the preview's pixels are clipped" not in _plan(as_shot, tmp_path / "a.lp")

    bright = np.clip(lit * 3.0, 0.0, 1.0)
    share = float((bright >= 1.0).all(axis=2).mean())
    assert share > PREVIEW_CLIPPED_LIMIT
    cases = {
        "16.tif": (np.round(bright * 65535).astype(np.uint16), 65535),
        "12.tif": (np.round(bright * 4095).astype(np.uint16), 4095),  # a 12-bit camera's
        "8.png": (linear_to_srgb8(np.round(bright * 65535).astype(np.uint16), 65535), 255),
    }
    for name, (pixels, top) in cases.items():
        path = tmp_path / name
        if name.endswith(".png"):
            cv2.imwrite(str(path), pixels[..., ::-1])
        else:
            tifffile.imwrite(path, pixels)
        text = _plan(path, tmp_path / f"{name}.lp")
        # at 8 bits, linear values a hair under white round to 255 too
        share = float((pixels >= top).all(axis=2).mean())
        assert share > PREVIEW_CLIPPED_LIMIT
        assert f"{share:.0%} of the preview's pixels are clipped (at {top} in every" in text, text
        # the command offered runs as pasted: the rig's config and a preview folder
        config = CONFIGS / "simulated_dome.toml"
        assert f"shoot the preview with less exposure (rti-rig preview {config} --out " in text
        assert "--auto-exposure meters one)" in text, text

    # one channel at its top (a vivid red object) keeps its shading in the others: no note
    red = np.round(lit * 65535).astype(np.uint16)
    red[: red.shape[0] // 2, :, 0] = 65535
    one_channel = tmp_path / "red.tif"
    tifffile.imwrite(one_channel, red)
    assert "of the preview's pixels are clipped" not in _plan(one_channel, tmp_path / "r.lp")
