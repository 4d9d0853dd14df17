"""Image files of a session: linear 16-bit TIFF for fitting, 8-bit sRGB JPEG for viewers.

Writes are atomic (temporary file in the same folder, fsync, rename) and never replace an
existing file, so an interrupted or repeated write can never damage an image already captured.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
from pathlib import Path

import cv2
import numpy as np
import tifffile
from numpy.typing import NDArray

from rti_rig.core.errors import SessionError


def linear_to_srgb8(pixels: NDArray[np.uint16], white_level: int) -> NDArray[np.uint8]:
    """Encode linear data with the sRGB transfer curve into 8 bits (for viewers and relight)."""
    x = np.clip(pixels.astype(np.float32) / float(white_level), 0.0, 1.0)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)
    return np.round(srgb * 255.0).astype(np.uint8)


def _atomic_write(path: Path, data: bytes) -> str:
    """Write bytes to a new file atomically; return its SHA-256."""
    if path.exists():
        raise SessionError(f"{path} already exists: refusing to overwrite a captured file")
    tmp = path.with_name(f".{path.name}.partial")
    try:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError:
        # a write that failed (no space, read-only, I/O error) leaves no partial file behind
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)
        raise
    return hashlib.sha256(data).hexdigest()


def write_linear_tiff(path: Path, pixels: NDArray[np.uint16]) -> str:
    """Write a linear 16-bit TIFF; returns its SHA-256."""
    import io

    buf = io.BytesIO()
    photometric = "rgb" if pixels.ndim == 3 else "minisblack"
    tifffile.imwrite(buf, pixels, photometric=photometric, compression="zlib")
    return _atomic_write(path, buf.getvalue())


def write_srgb_jpeg(path: Path, srgb8: NDArray[np.uint8], quality: int = 95) -> str:
    """Write an 8-bit sRGB JPEG (RGB order in, as OpenCV wants BGR on disk); returns SHA-256."""
    img = srgb8[..., ::-1] if srgb8.ndim == 3 else srgb8
    ok, enc = cv2.imencode(".jpg", np.ascontiguousarray(img), [cv2.IMWRITE_JPEG_QUALITY, quality])
    if not ok:
        raise SessionError(f"could not encode {path.name} as JPEG")
    return _atomic_write(path, enc.tobytes())


def read_linear_tiff(path: Path) -> NDArray[np.uint16]:
    return tifffile.imread(path)


def read_jpeg_rgb(path: Path) -> NDArray[np.uint8]:
    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise SessionError(f"cannot read image {path}")
    return img[..., ::-1] if img.ndim == 3 else img
