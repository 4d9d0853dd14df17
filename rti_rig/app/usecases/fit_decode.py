"""JPEG/PNG decoding for `rti-rig fit` into a buffer that is reused, image after image.

A fit decodes every compressed image of an acquisition once (two threads on this machine) and
writes it to a temporary file. ``cv2.imread(path)`` allocates the result and, in OpenCV 5, about
as much again while it decodes: 15 MB per image at 2.5 MP, 30 MB with two threads — the
largest transient of a normals fit whose whole budget is relight's 108 MB (issue #29).
OpenCV ≥ 4.10 decodes into a given array (``cv2.imread(path, dst, flags)``) with no second
buffer, so each decode thread keeps one image-sized buffer and reuses it.

That overload has a trap: when the file cannot be decoded it returns ``dst`` unchanged rather
than None — the previous image's pixels, silently. :func:`imread_into` therefore writes a
canary into the buffer's last row before decoding (the complement of what is there); a decode
overwrites every row, so a last row still equal to the canary means "not decoded" — or, very
rarely, an image whose last row happens to be that canary — and the file is decoded again the
ordinary way, which tells the two apart (None on failure). Where the overload does not exist
(OpenCV < 4.10) the ordinary way is used throughout.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from rti_rig.core import opencv_files
from rti_rig.core.image_files import png_colour_type
from rti_rig.core.opencv_files import opencv_name


def imread_rgb(path: Path, into: np.ndarray | None = None) -> np.ndarray | None:
    """The image at ``path`` as OpenCV reads it unchanged (8- or 16-bit, grey or colour), with
    colour images in RGB order, a grey + alpha PNG as grey, and an alpha channel dropped; None
    when it cannot be decoded. Decoded into ``into`` when that buffer has the image's shape and
    type (else into a new array)."""
    img = imread_into(path, into) if into is not None else _imread(path)
    if img is None:
        return None
    if img.ndim == 3 and img.shape[2] == 3 and img.dtype in (np.uint8, np.uint16):
        # BGR to RGB in place: a reversed copy would hold each image twice while it is written
        return cv2.cvtColor(img, cv2.COLOR_BGR2RGB, dst=img)
    if img.ndim == 3 and img.shape[2] == 4 and png_colour_type(path) == 4:
        # grey + alpha, which OpenCV reads as B = G = R = grey and alpha: grey, as its header
        # says (it had been fitted as colour); the alpha carries no light
        return np.ascontiguousarray(img[..., 0])
    if img.ndim == 3:
        # BGRA: the alpha sample carries no light and is dropped, as the replay rig reads such
        # images (reversed whole, RGBA had become ARGB, four channels the fit only refused at
        # its export)
        return np.ascontiguousarray(img[..., 2::-1] if img.shape[2] >= 3 else img[..., 0])
    return img


def imread_into(path: Path, buffer: np.ndarray) -> np.ndarray | None:
    """``cv2.imread(path, IMREAD_UNCHANGED)`` decoded into ``buffer`` when it fits (the result
    is then ``buffer`` itself), None when the file cannot be decoded (see the module's note on
    the canary)."""
    if buffer.ndim == 0 or buffer.shape[0] == 0:
        return _imread(path)
    canary = np.invert(buffer[-1])
    buffer[-1] = canary
    try:
        img = cv2.imread(opencv_name(path), buffer, cv2.IMREAD_UNCHANGED)
    except (cv2.error, TypeError):  # OpenCV < 4.10: no decoding into a given array
        return _imread(path)
    if img is None or img.size == 0:
        return None
    if img is buffer and np.array_equal(img[-1], canary):
        return _imread(path)  # not decoded, or a last row equal to the canary: ask plainly
    return img


def _imread(path: Path) -> np.ndarray | None:
    img = opencv_files.imread(path)
    return None if img is None or img.size == 0 else img
