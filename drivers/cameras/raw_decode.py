"""RAW files to linear 16-bit frames through rawpy (LibRaw), with nothing automatic.

Why a module of its own: every camera path that yields RAW (gphoto2 downloads, watched folders,
the simulated camera's DNGs) must produce *the same* linear data, so they all call
:func:`decode_raw`. The settings that matter for radiometry (checked against rawpy 0.28 /
LibRaw 0.22 with synthetic DNGs in tests/test_raw_decode.py):
gamma (1, 1), ``no_auto_bright``, 16-bit output, ``adjust_maximum_thr=0`` (the default 0.75
rescales to the data maximum and breaks linearity), a fixed white balance, no rotation.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np
import rawpy
from numpy.typing import NDArray
from rti_rig.drivers.cameras.settings import RawDecodeSettings

from rti_rig.core.devices import Frame
from rti_rig.core.errors import CaptureError

DECODER = "raw-decode"
_COLOR_NAMES = "RGBG"


def exposure_stats(
    pixels: NDArray[np.uint16], white_level: int, underexposed_level: float
) -> dict[str, float]:
    """Saturated and underexposed fractions of a linear frame (pure).

    A colour pixel counts as saturated if any channel is at white, and as underexposed if its
    brightest channel is at or below ``underexposed_level × white_level``.
    """
    px = pixels if pixels.ndim == 2 else pixels.max(axis=-1)
    return {
        "saturated_fraction": float(np.mean(px >= white_level)),
        "underexposed_fraction": float(np.mean(px <= underexposed_level * white_level)),
    }


def _source(source: Path | str | bytes) -> tuple[str, Any]:
    if isinstance(source, bytes | bytearray):
        return "<bytes>", io.BytesIO(bytes(source))
    path = Path(source)
    if not path.is_file():
        raise CaptureError(DECODER, f"RAW file not found: {path}", "decode")
    return str(path), str(path)


def _iso_from_tiff(source: Path | str | bytes) -> float:
    """ISOSpeedRatings from IFD0 or the EXIF IFD of TIFF-based RAWs (DNG, NEF, CR2, ARW).

    LibRaw ignores the tag in IFD0, where minimal DNGs (ours) carry it.
    """
    try:
        import tifffile

        handle = io.BytesIO(bytes(source)) if isinstance(source, bytes | bytearray) else source
        with tifffile.TiffFile(handle) as tif:
            page = tif.pages.first
            tag = page.tags.get(34855)
            if tag is not None:
                v = tag.value
                return float(v[0] if isinstance(v, tuple | list) else v)
            exif = page.tags.get(34665)
            if exif is not None and isinstance(exif.value, dict):
                v = exif.value.get("ISOSpeedRatings")
                if v is not None:
                    return float(v[0] if isinstance(v, tuple | list) else v)
    except Exception:  # not TIFF-based (CR3, RAF...): LibRaw's value stands
        return 0.0
    return 0.0


def _pattern_name(raw: rawpy.RawPy) -> str:
    pattern = np.asarray(raw.raw_pattern)
    desc = raw.color_desc.decode("ascii", "replace") if raw.color_desc else _COLOR_NAMES
    if pattern.shape != (2, 2):
        return f"{pattern.shape[0]}x{pattern.shape[1]}"
    return "".join(desc[int(i)] if int(i) < len(desc) else "?" for i in pattern.ravel())


def _postprocess_params(settings: RawDecodeSettings) -> dict[str, Any]:
    params: dict[str, Any] = {
        "gamma": (1, 1),
        "no_auto_bright": True,
        "output_bps": 16,
        "user_flip": 0,
        "adjust_maximum_thr": 0.0,
        "highlight_mode": rawpy.HighlightMode.Clip,
        "use_auto_wb": False,
        "output_color": rawpy.ColorSpace.raw
        if settings.output_color == "raw"
        else rawpy.ColorSpace.sRGB,
    }
    wb = settings.white_balance
    if wb == "unity":
        params["user_wb"] = [1.0, 1.0, 1.0, 1.0]
    elif wb == "camera":
        params["use_camera_wb"] = True
    else:
        params["user_wb"] = [float(x) for x in wb]
    if settings.mode == "half":
        params["half_size"] = True
    else:
        params["demosaic_algorithm"] = rawpy.DemosaicAlgorithm.LINEAR
    return params


def half_size_mask(mask: NDArray[np.bool_], h: int, w: int) -> NDArray[np.bool_]:
    """The photosite ``mask`` on LibRaw's h×w half-size output: a super-pixel is marked when
    any of its 2×2 photosites is. A sensor with an odd visible size has a last, incomplete
    row or column of super-pixels; the mask is padded (unmarked) to fit instead of failing."""
    full = np.zeros((2 * h, 2 * w), dtype=bool)
    rows, cols = min(mask.shape[0], 2 * h), min(mask.shape[1], 2 * w)
    full[:rows, :cols] = mask[:rows, :cols]
    return full.reshape(h, 2, w, 2).any(axis=(1, 3))


def _dilate(mask: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """3×3 dilation: a demosaiced pixel draws on its neighbours' photosites."""
    p = np.pad(mask, 1)
    out = np.zeros_like(mask)
    h, w = mask.shape
    for dy in range(3):
        for dx in range(3):
            out |= p[dy : dy + h, dx : dx + w]
    return out


def decode_raw(
    source: Path | str | bytes,
    settings: RawDecodeSettings | None = None,
    dark: Frame | None = None,
    timestamp_s: float | None = None,
) -> Frame:
    """Decode a RAW file (path or bytes) into a linear ``Frame``.

    Saturation is detected on the raw values *before* any processing (a saturated photosite
    marks its output pixel saturated: pinned at ``white_level``), so it survives dark
    subtraction and white balance. ``exposure_s`` and ``gain`` (ISO) come from the file's
    metadata (0.0 when absent); callers that set the exposure themselves record theirs too.
    """
    settings = settings or RawDecodeSettings()
    name, handle = _source(source)
    try:
        with rawpy.imread(handle) as raw:
            raw_vis = np.array(raw.raw_image_visible)  # uint16 copy out of LibRaw memory
            black_pc = np.asarray(raw.black_level_per_channel, dtype=np.int64)
            white = int(raw.white_level)
            pattern = _pattern_name(raw)
            other = raw.other
            if raw_vis.ndim != 2:
                raise CaptureError(DECODER, f"{name}: not a single-plane CFA RAW", "decode")
            white_level = int(white - black_pc.max())
            if white_level <= 0:
                raise CaptureError(
                    DECODER,
                    f"{name}: white level {white} is not above the "
                    f"black levels {black_pc.tolist()}",
                    "decode",
                )
            # Uniform black (the usual case) stays scalar: uint16 arithmetic, no index arrays.
            black: int | NDArray[np.int64] = (
                int(black_pc[0])
                if np.all(black_pc == black_pc[0])
                else black_pc[np.array(raw.raw_colors_visible)]
            )
            threshold = (
                int(black + np.floor(settings.saturation_level * (white - black)))
                if isinstance(black, int)
                else black + np.floor(settings.saturation_level * (white - black))
            )
            saturated = raw_vis >= threshold
            if settings.mode == "mosaic":
                if isinstance(black, int):
                    pixels = np.clip(raw_vis, black, black + white_level) - np.uint16(black)
                else:
                    pixels = np.clip(raw_vis.astype(np.int64) - black, 0, white_level)
                pixels = pixels.astype(np.uint16, copy=False)
                pixels[saturated] = white_level
            else:
                rgb = raw.postprocess(**_postprocess_params(settings))
                white_level = 65535
                pixels = np.asarray(rgb, dtype=np.uint16)
                h, w = pixels.shape[:2]
                if settings.mode == "half":
                    s = half_size_mask(saturated, h, w)
                else:
                    s = _dilate(saturated)[:h, :w]
                pixels[s] = white_level
    except rawpy.LibRawError as exc:
        raise CaptureError(
            DECODER,
            f"{name}: LibRaw cannot decode this file ({type(exc).__name__}: {exc}); "
            "is it a complete RAW/DNG download?",
            "decode",
        ) from exc
    iso = float(other.iso_speed) or _iso_from_tiff(source)
    exposure = float(other.shutter_speed)
    if timestamp_s is None:
        timestamp_s = Path(name).stat().st_mtime if name != "<bytes>" else 0.0
    metadata: dict[str, Any] = {
        "source_file": None if name == "<bytes>" else name,
        "decode_mode": settings.mode,
        "white_balance": settings.white_balance,
        "output_color": settings.output_color if settings.mode != "mosaic" else "raw",
        "cfa_pattern": pattern,
        "raw_black_level": [int(b) for b in black_pc],
        "raw_white_level": white,
        "exposure_s_from_file": exposure or None,
        "iso_from_file": iso or None,
        "aperture_from_file": float(other.aperture) or None,
        "dark_subtracted": False,
    }
    metadata.update(exposure_stats(pixels, white_level, settings.underexposed_level))
    frame = Frame(
        pixels=pixels,
        exposure_s=exposure,
        gain=iso,
        white_level=white_level,
        timestamp_s=float(timestamp_s),
        metadata=metadata,
    )
    if dark is not None:
        frame = subtract_dark(frame, dark, settings.underexposed_level)
    return frame


def subtract_dark(frame: Frame, dark: Frame, underexposed_level: float = 0.001) -> Frame:
    """Subtract a dark frame (same decode settings, same exposure) from a linear frame (pure).

    Saturated pixels stay pinned at the white level: a clipped pixel minus a dark is *not* a
    valid measurement, and keeping it at white keeps it flagged.
    """
    if dark.pixels.shape != frame.pixels.shape:
        raise CaptureError(
            DECODER,
            f"dark frame shape {dark.pixels.shape} does not match image {frame.pixels.shape}; "
            "decode the dark with the same settings (mode) as the images",
            "dark",
        )
    if dark.white_level != frame.white_level:
        raise CaptureError(
            DECODER,
            f"dark frame white level {dark.white_level} differs from the image's "
            f"{frame.white_level}; decode both with the same settings",
            "dark",
        )
    if frame.exposure_s > 0 and dark.exposure_s > 0:
        rel = abs(dark.exposure_s - frame.exposure_s) / frame.exposure_s
        if rel > 0.01:
            raise CaptureError(
                DECODER,
                f"dark frame exposure {dark.exposure_s:g} s differs from the image's "
                f"{frame.exposure_s:g} s; take darks at the session exposure",
                "dark",
            )
    px = frame.pixels.astype(np.int64)
    out = np.clip(px - dark.pixels.astype(np.int64), 0, frame.white_level)
    out[px >= frame.white_level] = frame.white_level
    pixels = out.astype(np.uint16)
    metadata = dict(frame.metadata)
    metadata["dark_subtracted"] = True
    metadata["dark_file"] = dark.metadata.get("source_file")
    metadata.update(exposure_stats(pixels, frame.white_level, underexposed_level))
    return Frame(
        pixels=pixels,
        exposure_s=frame.exposure_s,
        gain=frame.gain,
        white_level=frame.white_level,
        timestamp_s=frame.timestamp_s,
        metadata=metadata,
    )


def average_frames(frames: list[Frame]) -> Frame:
    """Mean of several frames (a master dark), rounded to uint16 (pure)."""
    if not frames:
        raise ValueError("average_frames needs at least one frame")
    first = frames[0]
    for f in frames[1:]:
        if f.pixels.shape != first.pixels.shape or f.white_level != first.white_level:
            raise ValueError("frames to average must share shape and white level")
    mean = np.mean([f.pixels.astype(np.float64) for f in frames], axis=0)
    metadata = dict(first.metadata)
    metadata["averaged_from"] = [f.metadata.get("source_file") for f in frames]
    return Frame(
        pixels=np.rint(mean).astype(np.uint16),
        exposure_s=first.exposure_s,
        gain=first.gain,
        white_level=first.white_level,
        timestamp_s=first.timestamp_s,
        metadata=metadata,
    )
