"""A file's colours, as its file says them, to linear sRGB: its transfer curve undone, its
primaries converted by the standard matrices, out-of-gamut values clipped and counted.

Why: a session's frames are taken as linear sRGB (the normals, the fits, the relight and
RTIBuilder exports read them so), but a ProPhoto TIFF from Lightroom is gamma 1.8, a 16-bit
sRGB TIFF or PNG is sRGB-encoded, and Adobe RGB, ProPhoto and Display P3 files have other
primaries: taken as they were, the fits were of gamma-encoded values and the colours of
another space under an sRGB name. Converted here, every known space becomes what the session
says it is; a file whose space is not known is left as it was, and said to be so
(:func:`~rti_rig.drivers.cameras.file_colour.file_colour_notice`).

Why not Pillow's ImageCms (Pillow is installed): it transforms 8-bit modes only (no 16-bit
RGB), so a 16-bit TIFF would lose its depth, and it clips out-of-gamut colours without
saying how many. The matrices are few and the specs publish their constants.

Sources (constants only):

* sRGB: IEC 61966-2-1:1999, 5.2 (primaries R 0.64,0.33 G 0.30,0.60 B 0.15,0.06, D65
  0.3127,0.3290) and 5.3 (decoding: V/12.92 for V <= 0.04045, else ((V+0.055)/1.055)^2.4).
* Adobe RGB (1998) Color Image Encoding, version 2005-05: 4.2 (primaries R 0.64,0.33
  G 0.21,0.71 B 0.15,0.06, D65) and 4.3.1.2 (a pure power, gamma 563/256 = 2.19921875, no
  linear toe).
* ROMM RGB (ProPhoto RGB), ISO 22028-2:2013 / ANSI/I3A IT10.7666:2003: primaries R
  0.7347,0.2653 G 0.1596,0.8404 B 0.0366,0.0001, white D50 0.3457,0.3585; decoding E'/16 for
  E' < 16 Et (Et = 1/512), else E'^1.8.
* Display P3 (Apple; SMPTE EG 432-1 primaries R 0.680,0.320 G 0.265,0.690 B 0.150,0.060)
  with the D65 white and the sRGB curve.
* D50 to D65: the linear Bradford transform (ICC.1:2010 Annex E), as ICC profiles adapt.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from rti_rig.drivers.cameras.file_colour import FileColour

Curve = Literal["srgb", "adobe_rgb", "prophoto", "linear"]

_D65 = (0.3127, 0.3290)
_D50 = (0.3457, 0.3585)


@dataclass(frozen=True)
class Space:
    """A known space: its primaries and white (CIE 1931 xy), its curve, and the words for both."""

    primaries: tuple[tuple[float, float], tuple[float, float], tuple[float, float]]
    white: tuple[float, float]
    curve: Curve
    curve_words: str


SPACES: dict[str, Space] = {
    "srgb": Space(
        ((0.64, 0.33), (0.30, 0.60), (0.15, 0.06)), _D65, "srgb", "the sRGB curve (IEC 61966-2-1)"
    ),
    "adobe_rgb": Space(
        ((0.64, 0.33), (0.21, 0.71), (0.15, 0.06)),
        _D65,
        "adobe_rgb",
        "Adobe RGB (1998)'s gamma 563/256",
    ),
    "prophoto": Space(
        ((0.7347, 0.2653), (0.1596, 0.8404), (0.0366, 0.0001)),
        _D50,
        "prophoto",
        "ROMM RGB's gamma 1.8 with its linear toe (ISO 22028-2)",
    ),
    "display_p3": Space(
        ((0.680, 0.320), (0.265, 0.690), (0.150, 0.060)),
        _D65,
        "srgb",
        "the sRGB curve (Display P3's own)",
    ),
}

#: the linear Bradford cone response matrix (ICC.1:2010 Annex E)
_BRADFORD = np.array(
    [[0.8951, 0.2664, -0.1614], [-0.7502, 1.7135, 0.0367], [0.0389, -0.0685, 1.0296]]
)


def _white_xyz(xy: tuple[float, float]) -> NDArray[np.float64]:
    x, y = xy
    return np.array([x / y, 1.0, (1 - x - y) / y])


def rgb_to_xyz(space: Space) -> NDArray[np.float64]:
    """The matrix from linear RGB of ``space`` to XYZ (Y of its white = 1), from its primaries
    and white (SMPTE RP 177-1993, 3.3: each primary's XYZ scaled so that RGB 1,1,1 is white)."""
    p = np.array([[x / y, 1.0, (1 - x - y) / y] for x, y in space.primaries]).T
    scale = np.linalg.solve(p, _white_xyz(space.white))
    return p * scale


def _bradford(source: tuple[float, float], target: tuple[float, float]) -> NDArray[np.float64]:
    """XYZ under ``source`` white to XYZ under ``target`` white (identity for the same)."""
    if source == target:
        return np.eye(3)
    s, t = _BRADFORD @ _white_xyz(source), _BRADFORD @ _white_xyz(target)
    return np.linalg.inv(_BRADFORD) @ np.diag(t / s) @ _BRADFORD


def to_srgb_matrix(space: str) -> NDArray[np.float64]:
    """Linear RGB of ``space`` to linear sRGB (each row sums to 1: white stays white)."""
    srgb = SPACES["srgb"]
    source = SPACES[space]
    return (
        np.linalg.inv(rgb_to_xyz(srgb)) @ _bradford(source.white, srgb.white) @ rgb_to_xyz(source)
    )


def decode_curve(v: NDArray[np.float64], curve: Curve) -> NDArray[np.float64]:
    """Encoded values (0..1) to linear light (0..1) by ``curve`` (pure)."""
    if curve == "srgb":
        return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
    if curve == "adobe_rgb":
        return v ** (563 / 256)
    if curve == "prophoto":
        return np.where(v < 16 / 512, v / 16, v**1.8)
    return v


#: rows converted at a time (bounds the float working set to a band of the frame)
_ROWS = 256


@dataclass(frozen=True)
class Converted:
    """The frame's pixels in linear sRGB (uint16, white 65535) and what was done to them, in
    words for the step's ``file_colour`` record."""

    pixels: NDArray[np.uint16]
    record: dict[str, str]
    clipped: int


def needs_conversion(colour: FileColour | None, dtype: np.dtype) -> bool:
    """Whether a file of ``colour`` and ``dtype`` is converted: a known space other than sRGB,
    or a 16-bit sRGB file whose ICC profile or Exif ColorSpace says sRGB, its curve not
    linear (its curve undone; one said sRGB by its Exif ColorSpace alone and written by dcraw
    or LibRaw is taken as linear, their linear TIFFs carrying that tag copied from the camera:
    :func:`~rti_rig.drivers.cameras.file_colour.exif_only_16_bit_notice`), or an 8-bit sRGB
    file whose ICC profile's curve is linear (taken as linear, as the profile says, whatever
    ``eight_bit_response`` says: it had been read through the sRGB table). Any other 8-bit
    sRGB file keeps its readers' own sRGB tables (the same curve); an unknown or unsaid space
    is left.
    Only 8- and 16-bit values are: a float or 32-bit file goes on to its reader's refusal of
    its pixel type (its values had indexed the curve's table: a traceback ended the run)."""
    if colour is None or colour.space not in SPACES or dtype not in (np.uint8, np.uint16):
        return False
    if colour.space != "srgb":
        return True
    if dtype == np.uint8:  # its ICC profile's linear curve wins over the sRGB table
        return colour.linear_curve
    return not colour.linear_curve and not colour.exif_linear


def to_linear_srgb(image: NDArray, colour: FileColour, *, encoded: bool = True) -> Converted:
    """``image`` (H×W×3, RGB order, uint8 or uint16, as the file stores it) in linear sRGB.

    ``encoded``: its values carry the space's curve (False: the user asserts the values are
    linear, an 8-bit file read with ``eight_bit_response = "linear"``); a file whose ICC
    profile's curve is the identity is linear whatever this says. A pixel whose converted
    value falls outside 0..1 in any channel (a colour sRGB cannot show) is clipped to it and
    counted: the count is the record's, never silent."""
    space = SPACES[colour.space]
    curve: Curve = space.curve if encoded and not colour.linear_curve else "linear"
    top = 255 if image.dtype == np.uint8 else 65535
    lut = decode_curve(np.arange(top + 1, dtype=np.float64) / top, curve).astype(np.float32)
    matrix = to_srgb_matrix(colour.space).astype(np.float32).T
    half = np.float32(0.5 / 65535)  # beyond half a code: out of gamut, not rounding
    pixels = np.empty((*image.shape[:2], 3), np.uint16)
    clipped = 0
    for row in range(0, image.shape[0], _ROWS):  # in bands: a 24 MP frame's floats in one
        linear = lut[image[row : row + _ROWS, :, :3]]  # piece had held about 1 GB
        if colour.space != "srgb":
            linear = linear @ matrix
            out = (linear < -half) | (linear > 1 + half)
            clipped += int(np.count_nonzero(out.any(axis=-1)))
        np.clip(linear, 0.0, 1.0, out=linear)
        linear *= 65535
        pixels[row : row + _ROWS] = np.rint(linear, out=linear)
    curve_words = (
        "none: linear, as its ICC profile's curve (gamma 1.0) says"
        if colour.linear_curve
        else space.curve_words
        if encoded
        else "none: linear, as the config's eight_bit_response says"
    )
    record = {
        "curve_undone": curve_words,
        "primaries": (
            "sRGB's, kept"
            if colour.space == "srgb"
            else f"converted from {colour.name}'s to sRGB's (the specs' matrices"
            + (", Bradford D50 to D65)" if space.white != _D65 else ")")
        ),
        "out_of_gamut_clipped": f"{clipped} of {image.shape[0] * image.shape[1]} pixels",
    }
    return Converted(pixels, record, clipped)


def converted_notice(colour: FileColour, whose: str = "the camera's files") -> str:
    """The session notice for files converted to linear sRGB (one text for every image, so
    the session counts the images it concerns)."""
    return (
        f"{whose} are {colour.name} (said by {colour.said_by}): rti-rig undid its curve and "
        "converted its primaries to sRGB's for the session's images (the files kept under "
        "raw/ are untouched); each step's file_colour in the manifest says what was done"
    )


def clipped_notice(colour: FileColour) -> str:
    """The session notice for an image some of whose colours sRGB cannot show."""
    return (
        f"some colours of the {colour.name} files lie outside sRGB's gamut and were clipped "
        "to it in the session's images (each step's file_colour.out_of_gamut_clipped counts "
        "the pixels; the files kept under raw/ keep them)"
    )
