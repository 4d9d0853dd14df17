"""Write minimal DNG files from linear sensor data, with tifffile only.

Why: tests and the simulated camera need RAW files that go through exactly the same rawpy
decode path as a real camera's, without shipping camera files. A DNG is a TIFF whose IFD0 carries
a few extra tags; LibRaw needs DNGVersion, CFARepeatPatternDim and CFAPattern, and reads
BlackLevel/WhiteLevel and ExposureTime from IFD0. (ISO is only read by LibRaw from an EXIF IFD,
so ``raw_decode`` reads the ISOSpeedRatings tag written here with tifffile.) Without
BlackLevel/WhiteLevel LibRaw assumes 0 and 65535; images under 22×22 pixels are refused.
"""

from __future__ import annotations

import io
from fractions import Fraction
from pathlib import Path

import numpy as np
import tifffile
from numpy.typing import NDArray

# DNG CFAPattern colour codes: 0 = red, 1 = green, 2 = blue; pattern read row by row.
CFA_CODES: dict[str, tuple[int, int, int, int]] = {
    "RGGB": (0, 1, 1, 2),
    "BGGR": (2, 1, 1, 0),
    "GRBG": (1, 0, 2, 1),
    "GBRG": (1, 2, 0, 1),
}

# LibRaw's identify() refuses images narrower or shorter than 22 pixels (found by experiment:
# 20×20 is "Unsupported file format", 22×22 decodes).
MIN_SIDE = 22

TAG_MAKE = 271
TAG_DATE_TIME = 306
TAG_MODEL = 272
TAG_CFA_REPEAT = 33421
TAG_CFA_PATTERN = 33422
TAG_EXPOSURE_TIME = 33434
TAG_FNUMBER = 33437
TAG_ISO = 34855
TAG_DNG_VERSION = 50706
TAG_UNIQUE_MODEL = 50708
TAG_BLACK_REPEAT = 50713
TAG_BLACK_LEVEL = 50714
TAG_WHITE_LEVEL = 50717
TAG_AS_SHOT_NEUTRAL = 50728


def _rational(value: float, max_den: int = 1_000_000) -> tuple[int, int]:
    f = Fraction(value).limit_denominator(max_den)
    return f.numerator, f.denominator


def dng_bytes(
    mosaic: NDArray[np.uint16],
    cfa_pattern: str = "RGGB",
    black_level: int | tuple[int, int, int, int] = 0,
    white_level: int = 65535,
    exposure_s: float | None = None,
    iso: int | None = None,
    f_number: float | None = None,
    make: str = "rti-rig",
    model: str = "simulated",
    as_shot_neutral: tuple[float, float, float] | None = None,
    date_time: str | None = None,
) -> bytes:
    """Encode a Bayer mosaic (uint16, H×W, even sizes) as an uncompressed DNG and return bytes.

    ``mosaic`` holds raw code values *including* the black offset, as a sensor delivers them.
    ``black_level`` is one value, or four for the 2×2 positions row by row (written with
    BlackLevelRepeatDim, as cameras with per-channel black levels do). ``date_time``
    ("YYYY:MM:DD HH:MM:SS", the camera's clock, whole seconds) is written as IFD0's DateTime,
    which LibRaw reads as the capture time (rawpy's ``other.timestamp``).
    """
    arr = np.asarray(mosaic)
    if arr.dtype != np.uint16 or arr.ndim != 2:
        raise ValueError(f"mosaic must be a 2-D uint16 array, got {arr.dtype} {arr.shape}")
    if arr.shape[0] % 2 or arr.shape[1] % 2:
        raise ValueError(f"mosaic sizes must be even for a 2×2 CFA, got {arr.shape}")
    if min(arr.shape) < MIN_SIDE:
        raise ValueError(
            f"mosaic must be at least {MIN_SIDE}×{MIN_SIDE}: LibRaw rejects smaller images as "
            f"'not RAW', got {arr.shape}"
        )
    if cfa_pattern not in CFA_CODES:
        raise ValueError(f"cfa_pattern must be one of {sorted(CFA_CODES)}, got {cfa_pattern!r}")
    blacks = (black_level,) if isinstance(black_level, int) else tuple(black_level)
    if len(blacks) not in (1, 4) or not all(0 <= b < white_level <= 65535 for b in blacks):
        raise ValueError(
            f"need 0 <= black_level < white_level <= 65535 (one or four black "
            f"levels), got {black_level}, {white_level}"
        )
    tags: list[tuple[int, str, int, object, bool]] = [
        (TAG_DNG_VERSION, "B", 4, (1, 4, 0, 0), True),
        (TAG_UNIQUE_MODEL, "s", 0, f"{make} {model}", True),
        (TAG_MAKE, "s", 0, make, True),
        (TAG_MODEL, "s", 0, model, True),
        (TAG_CFA_REPEAT, "H", 2, (2, 2), True),
        (TAG_CFA_PATTERN, "B", 4, CFA_CODES[cfa_pattern], True),
        (TAG_BLACK_LEVEL, "H", len(blacks), blacks if len(blacks) > 1 else blacks[0], True),
        (TAG_WHITE_LEVEL, "H", 1, int(white_level), True),
    ]
    if len(blacks) == 4:
        tags.append((TAG_BLACK_REPEAT, "H", 2, (2, 2), True))
    if exposure_s is not None:
        if exposure_s <= 0:
            raise ValueError(f"exposure_s must be positive, got {exposure_s}")
        tags.append((TAG_EXPOSURE_TIME, "2I", 1, _rational(exposure_s), True))
    if f_number is not None:
        tags.append((TAG_FNUMBER, "2I", 1, _rational(f_number, 1000), True))
    if iso is not None:
        tags.append((TAG_ISO, "H", 1, int(iso), True))
    if as_shot_neutral is not None:
        flat: list[int] = []
        for v in as_shot_neutral:
            flat.extend(_rational(v, 10_000))
        tags.append((TAG_AS_SHOT_NEUTRAL, "2I", 3, tuple(flat), True))
    if date_time is not None:
        tags.append((TAG_DATE_TIME, "s", 0, date_time, True))
    buf = io.BytesIO()
    tifffile.imwrite(buf, arr, photometric=tifffile.PHOTOMETRIC.CFA, extratags=tags, metadata=None)
    return buf.getvalue()


def write_dng(path: Path | str, mosaic: NDArray[np.uint16], **kwargs: object) -> Path:
    """Write :func:`dng_bytes` to ``path`` (parents must exist); returns the path."""
    p = Path(path)
    p.write_bytes(dng_bytes(mosaic, **kwargs))  # type: ignore[arg-type]
    return p


def linear_to_mosaic(
    linear: NDArray[np.floating],
    cfa_pattern: str = "RGGB",
    black_level: int = 0,
    white_level: int = 65535,
) -> NDArray[np.uint16]:
    """Sample linear scene data onto a Bayer mosaic of raw code values.

    ``linear`` is H×W×3 RGB (or H×W grey) in units of the sensor's full scale: 0 is black,
    1 is the white level; values above 1 clip there, as a real sensor saturates. Returns
    ``black + round(v × (white − black))`` as uint16. Pure: the simulator adds noise before.
    """
    lin = np.asarray(linear, dtype=np.float64)
    if cfa_pattern not in CFA_CODES:
        raise ValueError(f"cfa_pattern must be one of {sorted(CFA_CODES)}, got {cfa_pattern!r}")
    if lin.ndim == 3:
        if lin.shape[2] != 3:
            raise ValueError(f"linear must be H×W×3 or H×W, got {lin.shape}")
        codes = CFA_CODES[cfa_pattern]
        h, w = lin.shape[:2]
        chan = np.empty((h, w), dtype=np.intp)
        chan[0::2, 0::2] = codes[0]
        chan[0::2, 1::2] = codes[1]
        chan[1::2, 0::2] = codes[2]
        chan[1::2, 1::2] = codes[3]
        plane = np.take_along_axis(lin, chan[..., None], axis=2)[..., 0]
    elif lin.ndim == 2:
        plane = lin
    else:
        raise ValueError(f"linear must be H×W×3 or H×W, got {lin.shape}")
    if not np.all(np.isfinite(plane)):
        raise ValueError("linear data contains NaN or infinity")
    scaled = black_level + np.rint(np.clip(plane, 0.0, 1.0) * (white_level - black_level))
    return scaled.astype(np.uint16)
