"""A camera RAW file as the planner's preview: decoded linearly, planned like its linear TIFF.

The DNGs are written by the test itself (``rti_rig.drivers.cameras.dng_writer``), no camera files.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import tifffile
from conftest import REPO
from typer.testing import CliRunner

from rti_rig.app.compose import read_preview_image
from rti_rig.cli import app
from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.core.lp_format import read_lp
from rti_rig.drivers.cameras.dng_writer import linear_to_mosaic, write_dng
from rti_rig.planner.topography import planning_image

BLACK, WHITE = 512, 16383  # a 14-bit sensor with a black pedestal
LIGHT = (45.0, 50.0)


def shaded_relief(size: int = 512) -> np.ndarray:
    """Linear grey shading (fraction of full scale) of a bumpy relief under :data:`LIGHT`:
    asymmetric on purpose, so that a flipped or rotated decode would not match."""
    y, x = np.mgrid[0:size, 0:size] / size
    h = 6 * np.exp(-((x - 0.3) ** 2 + (y - 0.6) ** 2) / 0.02) + 3 * np.sin(9 * x) * y
    gy, gx = np.gradient(h)
    n = np.dstack([-gx, gy, np.ones_like(h)])  # rows run down, y up (docs/conventions.md frame)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    shade = np.clip(n @ direction_from_az_el(*LIGHT), 0.0, None)
    return 0.05 + 0.8 * shade * (0.6 + 0.4 * x)  # some albedo variation, below saturation


def shot_files(folder: Path, name: str) -> tuple[Path, Path]:
    """The same scene as a 14-bit RAW (DNG, ``name``) and as a 16-bit linear TIFF beside it."""
    linear = shaded_relief()
    dng = write_dng(
        folder / name,
        linear_to_mosaic(linear, "RGGB", BLACK, WHITE),
        black_level=BLACK,
        white_level=WHITE,
    )
    tif = dng.with_suffix(".tif")
    tifffile.imwrite(tif, np.round(linear * 65535).astype(np.uint16))
    return dng, tif


def test_a_raw_preview_decodes_to_the_planning_image_of_its_linear_data(tmp_path: Path) -> None:
    """Same planning image (within rounding) as the 16-bit linear TIFF of the same scene:
    linear, scaled to full range, black level removed, not flipped or rotated."""
    dng, tif = shot_files(tmp_path, "preview.DNG")
    raw = read_preview_image(dng)
    assert raw.dtype == np.uint16 and raw.ndim == 3  # linear 16-bit RGB, half resolution
    from_raw, from_tif = planning_image(raw), planning_image(read_preview_image(tif))
    assert from_raw.shape == from_tif.shape
    np.testing.assert_allclose(from_raw, from_tif, atol=0.01)
    assert abs(np.corrcoef(from_raw.ravel(), from_tif.ravel())[0, 1] - 1) < 1e-3


@pytest.mark.slow
def test_plan_takes_a_raw_preview_and_refuses_a_broken_one_by_name(tmp_path: Path) -> None:
    """The same lights as from the scene's linear TIFF; a file LibRaw cannot read is refused,
    named, with what to give instead, and no plan is written."""
    dng, tif = shot_files(tmp_path, "shot.dng")
    rig = REPO / "rig_configs" / "simulated_dome.toml"
    args = ["--rig", str(rig), "--lights", "9", "--preview-light", "45,50"]
    plans = []
    for source in (dng, tif):
        plan = tmp_path / f"plan_{source.suffix[1:]}.lp"
        r = CliRunner().invoke(app, ["plan", str(source), *args, "--out", str(plan)])
        assert r.exit_code == 0, r.output
        plans.append(np.array([e.direction for e in read_lp(plan)]))
    assert len(plans[0]) == 9
    np.testing.assert_allclose(plans[0], plans[1], atol=1e-6)  # the same lights, same order

    broken = tmp_path / "broken.CR2"
    broken.write_bytes(b"not a raw file at all")
    plan = tmp_path / "plan_broken.lp"
    r = CliRunner().invoke(app, ["plan", str(broken), *args, "--out", str(plan)])
    assert r.exit_code != 0
    assert "broken.CR2" in r.output and "RAW" in r.output and "TIFF" in r.output
    assert not plan.exists()


def test_a_missing_raw_preview_is_named() -> None:
    with pytest.raises(ScheduleError, match=r"absent\.nef: preview image not found"):
        read_preview_image(Path("absent.nef"))


def test_a_raw_preview_keeps_its_colour_channels_in_rgb_order(tmp_path: Path) -> None:
    """The planner weighs R, G and B as Rec. 709 luminance: a red-and-blue scene must come
    out red where it was red (a BGR swap would put it in the blue channel)."""
    size = 64
    linear = np.zeros((size, size, 3))
    linear[:, : size // 2] = (0.8, 0.1, 0.05)  # red left half
    linear[:, size // 2 :] = (0.05, 0.1, 0.8)  # blue right half
    dng = write_dng(
        tmp_path / "colour.dng",
        linear_to_mosaic(linear, "RGGB", BLACK, WHITE),
        black_level=BLACK,
        white_level=WHITE,
    )
    raw = read_preview_image(dng).astype(float) / 65535
    left, right = (
        raw[:, : size // 4 - 1].mean(axis=(0, 1)),
        raw[:, -(size // 4 - 1) :].mean(axis=(0, 1)),
    )
    np.testing.assert_allclose(left, (0.8, 0.1, 0.05), atol=0.01)
    np.testing.assert_allclose(right, (0.05, 0.1, 0.8), atol=0.01)


def test_plan_refuses_a_monochrome_raw_preview_in_a_previews_words(tmp_path: Path) -> None:
    """A monochrome sensor's DNG (LinearRaw, one sample) as plan's preview is refused, as the
    decode refuses it, but in words for a preview: the decode's own named a camera's
    ``[camera.device.decode] mode = "half"`` (plan's setting, in no config) and a watched
    folder's patterns, which plan has neither of. The grey 16-bit TIFF it advises plans."""
    from tests.dng_spec_writer import monochrome_dng

    linear = shaded_relief(256)
    grey = np.round(linear * 65535).astype("<u2")
    mono = tmp_path / "mono.dng"
    mono.write_bytes(monochrome_dng(grey))
    rig = REPO / "rig_configs" / "simulated_dome.toml"
    args = ["--rig", str(rig), "--lights", "9", "--preview-light", "45,50"]
    plan = tmp_path / "plan_mono.lp"
    r = CliRunner().invoke(app, ["plan", str(mono), *args, "--out", str(plan)])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"RAW preview {mono}: it is a monochrome sensor's file" in said, said
    assert "16-bit linear grey TIFF" in said, said
    assert "[camera.device.decode]" not in said and "patterns" not in said, said
    assert not plan.exists()
    tif = tmp_path / "mono.tif"
    tifffile.imwrite(tif, grey)
    r = CliRunner().invoke(app, ["plan", str(tif), *args, "--out", str(plan)])
    assert r.exit_code == 0, r.output
    assert len(read_lp(plan)) == 9
