"""The conversion to linear sRGB against the specs' own published numbers (not against
constants copied from the module): Adobe RGB (1998) 4.3.4.1's normalised RGB-to-XYZ
matrix, ROMM RGB's (ISO 22028-2) and IEC 61966-2-1's; ROMM's linear toe; and a profile
whose curve is linear (a session's own linear TIFF) is never given a curve to undo."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import tifffile

from rti_rig.core.image_colour import icc_profile
from rti_rig.drivers.cameras.colour_convert import (
    SPACES,
    decode_curve,
    needs_conversion,
    rgb_to_xyz,
    to_srgb_matrix,
)
from rti_rig.drivers.cameras.file_colour import file_colour


@pytest.mark.parametrize(
    ("space", "published"),
    [
        ("srgb", [[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]),
        (
            "adobe_rgb",
            [[0.57667, 0.18556, 0.18823], [0.29734, 0.62736, 0.07529], [0.02703, 0.07069, 0.99134]],
        ),
        ("prophoto", [[0.7977, 0.1352, 0.0313], [0.2880, 0.7119, 0.0001], [0.0, 0.0, 0.8249]]),
    ],
)
def test_the_primaries_give_the_specs_matrices(space: str, published: list) -> None:
    assert np.allclose(rgb_to_xyz(SPACES[space]), published, atol=6e-4)


def test_romm_rgb_is_linear_below_its_toe_and_gamma_1_8_above() -> None:
    v = np.array([0.0, 0.02, 16 / 512, 0.5, 1.0])
    want = [0.0, 0.02 / 16, (16 / 512) ** 1.8, 0.5**1.8, 1.0]
    assert np.allclose(decode_curve(v, "prophoto"), want)
    assert np.isclose(decode_curve(np.array([0.5]), "adobe_rgb")[0], 0.5**2.19921875)


def test_a_session_s_own_linear_tiff_is_taken_as_stored(tmp_path: Path) -> None:
    """Its linear-sRGB profile (gamma 1.0) says no curve: a replay of it stays identical;
    an sRGB-encoded 16-bit TIFF (the sRGB curve's profile) has its curve undone."""
    pixels = np.full((4, 4, 3), 20000, np.uint16)
    linear, encoded = tmp_path / "a.tif", tmp_path / "b.tif"
    tifffile.imwrite(linear, pixels, iccprofile=icc_profile("linear"))
    tifffile.imwrite(encoded, pixels, iccprofile=icc_profile("srgb"))
    assert file_colour(linear).linear_curve
    assert not needs_conversion(file_colour(linear), np.dtype(np.uint16))
    assert needs_conversion(file_colour(encoded), np.dtype(np.uint16))
    assert not needs_conversion(file_colour(encoded), np.dtype(np.uint8))


@pytest.mark.parametrize(
    ("space", "published"),
    [
        # CSS Color Module Level 4, 18 (sample code): lin_P3 to XYZ, then XYZ to lin_sRGB
        (
            "display_p3",
            [[1.2249, -0.2247, 0.0], [-0.0420, 1.0419, 0.0], [-0.0197, -0.0786, 1.0979]],
        ),
        # the same spec's lin_ProPhoto to XYZ (D50), Bradford D50 to D65, XYZ to lin_sRGB
        (
            "prophoto",
            [[2.0344, -0.7276, -0.3067], [-0.2288, 1.2317, -0.0029], [-0.0086, -0.1533, 1.1618]],
        ),
    ],
)
def test_the_whole_conversion_matches_a_published_one(space: str, published: list) -> None:
    """Primaries, white adaptation and sRGB's inverse together (the per-space matrices above
    do not reach the Bradford step nor the inversion)."""
    assert np.allclose(to_srgb_matrix(space), published, atol=6e-4)
