"""An imported acquisition of 12-bit camera data in 16-bit files is judged against its own
full scale, through ``rti-rig fit``.

Found by a fault sweep through the front door: the shipped simulated dome's session, its
linear TIFFs saved as machine-vision and scientific cameras save 12-bit data (16-bit files,
values up to 4095, unscaled), was fitted against 65535 as white. Exposed so that two thirds of
some images clipped at 4095 it was called "good" (its clipped highlights fitted as light);
exposed to a third of 4095 it was called "4.9 stops under-exposed", with the advice to give
it 29× the exposure. rti-rig's own sessions scale their camera's range to 65535 as they are
shot; an acquisition from elsewhere now has its full scale read from its images
(:mod:`rti_rig.reconstruct.full_scale`) or given (``--white-level``).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from colour_files import icc_profile
from conftest import said, shipped_variant
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import read_linear_tiff
from rti_rig.reconstruct.synthetic import camera_bits_copy

runner = CliRunner()


def _fit(source: Path, out: Path, *extra: str) -> tuple[str, dict, dict]:  # type: ignore[type-arg]
    r = runner.invoke(app, ["fit", str(source), "--out", str(out), "--no-ptm", "--no-hsh", *extra])
    assert r.exit_code == 0, r.output
    fit = json.loads((out / "fit.json").read_text())
    return said(r), fit, json.loads((out / "qa.json").read_text())


def test_twelve_bit_data_clipped_at_4095_is_named_saturated(
    dome_relief: Path, tmp_path: Path
) -> None:
    acquisition = camera_bits_copy(dome_relief, tmp_path / "acq", gain=3.0)
    text, fit, qa = _fit(acquisition, tmp_path / "f")

    assert qa["good"] is False, qa["verdict"]
    saturated = [c["name"] for c in qa["images"] if any("saturated" in p for p in c["problems"])]
    assert len(saturated) >= 6, qa["verdict"]
    # the QA's share of clipped pixels is of 4095, not of 65535 (which none reach)
    assert max(c["saturated_fraction"] for c in qa["images"]) > 0.2, qa["images"]
    assert fit["full_scale"]["level"] == 4095 and fit["full_scale"]["how"] == "clipped", fit
    assert fit["full_scale"]["bits"] == 12
    assert "are clipped at 4095, not at 65535 (12-bit data)" in text, text


def test_twelve_bit_data_shifted_up_and_clipped_is_named_saturated(
    dome_relief: Path, tmp_path: Path
) -> None:
    """Shifted up by 4 bits (every value a multiple of 16): the clip is at 65520."""
    acquisition = camera_bits_copy(dome_relief, tmp_path / "acq", gain=3.0, shift=4)
    text, fit, qa = _fit(acquisition, tmp_path / "f")

    assert qa["good"] is False, qa["verdict"]
    assert max(c["saturated_fraction"] for c in qa["images"]) > 0.2, qa["images"]
    assert fit["full_scale"]["level"] == 65520 and fit["full_scale"]["how"] == "clipped", fit
    assert "(12-bit data shifted up)" in text, text


def test_twelve_bit_data_at_a_third_of_its_range_is_not_called_under_exposed(
    dome_relief: Path, tmp_path: Path
) -> None:
    acquisition = camera_bits_copy(dome_relief, tmp_path / "acq", gain=0.5)
    text, fit, qa = _fit(acquisition, tmp_path / "f")

    assert "under-exposed" not in qa["verdict"], qa["verdict"]
    assert max(c["peak_level"] for c in qa["images"]) > 0.2, qa["images"]
    assert fit["full_scale"]["how"] == "bits" and fit["full_scale"]["level"] == 4095, fit
    assert "read as 12-bit camera data stored unscaled" in text, text
    assert "--white-level 65535" in text, text

    # the other reading, asked for, is judged as asked: 16-bit images, under-exposed
    read_albedo = np.load(tmp_path / "f" / "albedo.npy")
    text, fit, qa = _fit(acquisition, tmp_path / "as16", "--white-level", "65535")
    assert fit["full_scale"] == {
        "level": 65535,
        "how": "given",
        "bits": None,
        "brightest_sampled": fit["full_scale"]["brightest_sampled"],
        "clipped_image": None,
        "clipped_share": 0.0,
    }, fit
    assert "under-exposed throughout" in qa["verdict"], qa["verdict"]
    # the fit itself (not only its QA) was made on the scale read: albedo 65535 / 4095 × that
    # of the same images read at 65535
    as16 = np.load(tmp_path / "as16" / "albedo.npy")
    lit = as16 > np.percentile(as16, 50)
    ratio = float(np.median(read_albedo[lit] / as16[lit]))
    assert ratio == pytest.approx(65535 / 4095, rel=0.01), ratio


def test_a_white_level_below_the_images_values_is_refused_naming_the_image(
    dome_relief: Path, tmp_path: Path
) -> None:
    acquisition = camera_bits_copy(dome_relief, tmp_path / "acq", gain=0.5)
    out = tmp_path / "f"
    r = runner.invoke(app, ["fit", str(acquisition), "--out", str(out), "--white-level", "300"])

    assert r.exit_code == 2, r.output
    text = said(r)
    assert "--white-level 300: image_" in text and ", above it;" in text, text
    assert "Traceback" not in r.output
    assert not out.exists()  # refused before anything was written

    r = runner.invoke(app, ["fit", str(acquisition), "--out", str(out), "--white-level", "0"])
    assert r.exit_code == 2 and "give a code value from 1 to 65535" in said(r), r.output


def test_images_converted_from_the_space_their_file_says_are_not_read(
    dome_relief: Path, tmp_path: Path
) -> None:
    """Adobe RGB TIFFs are converted to linear sRGB on 65535: their values are no camera's
    codes, so no depth is read from them (nor can one be given). At a quarter of the relief's
    levels, encoded, their linear values stay under 4095: read, they would be "12-bit"."""
    acquisition = camera_bits_copy(
        dome_relief, tmp_path / "acq", gain=0.25, bits=16, icc=icc_profile("Adobe RGB (1998)")
    )
    _, fit, _ = _fit(acquisition, tmp_path / "f")
    # converted, as the file says (an image read as stored would say how: "read_as")
    assert fit["image_colour"] and all(
        c["space"] == "adobe_rgb" and "read_as" not in c for c in fit["image_colour"].values()
    ), fit
    assert fit["full_scale"] is None, fit

    r = runner.invoke(
        app, ["fit", str(acquisition), "--out", str(tmp_path / "g"), "--white-level", "4095"]
    )
    assert r.exit_code == 2, r.output
    assert "converted from the colour space its file says" in said(r), r.output


def test_a_dark_sessions_own_images_are_judged_against_65535(tmp_path: Path) -> None:
    """rti-rig's own linear TIFFs, scaled to 65535 as shot, are never re-read, in their
    session or copied out with their .lp (an acquisition by its layout, but rti-rig's files):
    the shipped dome at a fiftieth of its exposure, no value above 1023, would otherwise read
    as 10-bit data and be judged well exposed."""
    config = shipped_variant(
        tmp_path, "simulated_dome.toml", (("exposure_s = 0.05", "exposure_s = 0.001"),)
    )
    session = tmp_path / "dark"
    r = runner.invoke(
        app, ["run", str(config), "--out", str(session), "--lights", "12", "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    top = max(int(read_linear_tiff(p).max()) for p in (session / "linear").glob("*.tif"))
    assert top <= 1023, top  # what the 10-bit reading would take

    _, fit, qa = _fit(session, tmp_path / "f")
    assert "under-exposed throughout" in qa["verdict"], qa["verdict"]
    assert fit["full_scale"] is None, fit

    copied = tmp_path / "copied"
    copied.mkdir()
    lines = (session / "lights.lp").read_text().splitlines()
    for tif in sorted((session / "linear").glob("*.tif")):
        shutil.copy(tif, copied)
    (copied / "lights.lp").write_text(
        "\n".join([lines[0]] + [ln.replace(".jpg", ".tif") for ln in lines[1:]]) + "\n"
    )
    _, fit, qa = _fit(copied, tmp_path / "f2")
    assert "under-exposed throughout" in qa["verdict"], qa["verdict"]
    assert fit["full_scale"] is None, fit
