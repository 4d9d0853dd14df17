"""Files that viewers people already use open: ``.ptm``, HSH ``.rti``, relight ``.dome``, maps.

Formats, as published (no code copied):

* **PTM 1.2, ``PTM_FORMAT_RGB``** (Malzbender, Gelb, Wolters; HP Labs "PTM file format 1.2";
  the layout relight's ``LRti`` reader in cnr-isti-vclab/relight ``src/legacy_rti.cpp`` reads):
  text lines ``PTM_1.2``, ``PTM_FORMAT_RGB``, width, height, six scale floats, six integer
  biases, then bytes: for each colour plane R, G, B, for each scanline, for each pixel, the six
  coefficients a0..a5. Coefficient ``a_i = (byte - bias_i) × scale_i``. Scanlines run from the
  bottom of the image up (the origin of a PTM is its lower-left corner), and ``(l_u, l_v)`` are
  the light's projection with ``v`` up — the DESIGN.md frame.
* **HSH ``.rti``** (RTIViewer's format, as relight's ``LRti::loadHSH`` reads it): comment lines
  starting ``#`` (the first is ``#HSH1.2``), the file type ``3`` (HSH), ``width height 3``,
  ``terms basis_type element_size`` (we write ``2 1``: the basis type is ignored by readers,
  one byte per element), then ``terms`` little-endian float32 scales and ``terms`` biases,
  then bytes: scanlines from the bottom up, for each pixel, for each colour, for each term.
  Coefficient ``c = byte / 255 × scale_k + bias_k``. Our basis is the true HSH (order-3
  exponent 1.5, see :mod:`rti_rig.core.rti_bases`).
* **relight ``.dome``** (cnr-isti-vclab/relight, "Dome configuration file format"): JSON with
  ``diameter`` (cm), ``imageWidth`` (cm), ``verticalOffset`` (cm) and ``directions`` (unit
  vectors, z up, x right, y towards the top of the image) or ``positions`` (cm).

Coefficients are written in units of the fitted (linear) images × 255, quantised to 8 bits per
coefficient with one scale and bias per coefficient index (over all pixels and colours).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.reconstruct.errors import ReconstructionError

#: Coefficients are stored for images scaled to 0–255 (what PTM/RTI viewers display).
DISPLAY_SCALE = 255.0


def _rgb_planes(coefficients: NDArray[Any]) -> NDArray[np.float32]:
    """(p, H, W, 3) float32 from (p, H, W) grey or (p, H, W, C) colour coefficients."""
    c = np.asarray(coefficients, dtype=np.float32)
    if c.ndim == 3:
        c = np.repeat(c[..., None], 3, axis=-1)
    if c.shape[-1] != 3:
        raise ReconstructionError(f"export needs grey or RGB coefficients, got {c.shape}")
    return c


def _atomic_bytes(path: Path, chunks: list[bytes]) -> Path:
    tmp = path.with_name(path.name + ".part")
    with open(tmp, "wb") as fh:
        for chunk in chunks:
            fh.write(chunk)
    tmp.replace(path)
    return path


def write_ptm_rgb(path: Path, coefficients: NDArray[Any]) -> Path:
    """Write PTM coefficients (6, H, W[, 3]) in Malzbender order as ``PTM_FORMAT_RGB``."""
    c = _rgb_planes(coefficients) * np.float32(DISPLAY_SCALE)
    if c.shape[0] != 6:
        raise ReconstructionError(f"a PTM has 6 coefficients, got {c.shape[0]}")
    _, h, w, _ = c.shape
    lo = np.minimum(c.reshape(6, -1).min(axis=1), 0.0).astype(np.float64)
    hi = np.maximum(c.reshape(6, -1).max(axis=1), 0.0).astype(np.float64)
    scale = np.maximum((hi - lo) / 255.0, 1e-12)
    bias = np.clip(np.round(-lo / scale), 0, 255).astype(int)
    header = (
        "PTM_1.2\nPTM_FORMAT_RGB\n"
        f"{w}\n{h}\n"
        + " ".join(f"{s:.9g}" for s in scale)
        + "\n"
        + " ".join(str(b) for b in bias)
        + "\n"
    ).encode("ascii")
    chunks = [header]
    for ch in range(3):
        plane = c[..., ch]  # (6, H, W)
        q = np.round(plane / scale[:, None, None].astype(np.float32) + bias[:, None, None])
        q = np.clip(q, 0, 255).astype(np.uint8)
        chunks.append(np.ascontiguousarray(np.moveaxis(q, 0, -1)[::-1]).tobytes())
    return _atomic_bytes(path, chunks)


def write_hsh_rti(path: Path, coefficients: NDArray[Any]) -> Path:
    """Write HSH coefficients (terms, H, W[, 3]) in ``.rti`` index order as an HSH ``.rti``."""
    c = _rgb_planes(coefficients) * np.float32(DISPLAY_SCALE)
    terms, h, w, _ = c.shape
    if terms not in (4, 9, 16):
        raise ReconstructionError(f"HSH has 4, 9 or 16 terms, got {terms}")
    lo = c.reshape(terms, -1).min(axis=1).astype(np.float64)
    hi = c.reshape(terms, -1).max(axis=1).astype(np.float64)
    scale = np.maximum(hi - lo, 1e-12)
    header = f"#HSH1.2\n#written by rti-rig\n3\n{w} {h} 3\n{terms} 2 1\n".encode("ascii")
    q = np.round(
        (c - lo[:, None, None, None].astype(np.float32))
        / scale[:, None, None, None].astype(np.float32)
        * 255.0
    )
    q = np.clip(q, 0, 255).astype(np.uint8)  # (terms, H, W, 3)
    body = np.ascontiguousarray(np.transpose(q, (1, 2, 3, 0))[::-1])  # rows bottom-up, x, c, k
    chunks = [
        header,
        scale.astype("<f4").tobytes(),
        lo.astype("<f4").tobytes(),
        body.tobytes(),
    ]
    return _atomic_bytes(path, chunks)


def write_relight_dome(
    path: Path,
    directions: ArrayLike,
    *,
    diameter_cm: float | None = None,
    image_width_cm: float | None = None,
    label: str = "",
) -> Path:
    """relight's ``.dome`` JSON for these light ``directions`` (N, 3), z up, y to image top."""
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    doc: dict[str, Any] = {
        "label": label,
        "diameter": float(diameter_cm) if diameter_cm else 0.0,
        "imageWidth": float(image_width_cm) if image_width_cm else 0.0,
        "verticalOffset": 0.0,
        "directions": [[round(float(x), 6) for x in row] for row in d],
    }
    path.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    return path


def write_normal_map(stem: Path, normals: NDArray[Any]) -> list[Path]:
    """``stem.png`` (16-bit RGB, ``(n + 1) / 2``) and ``stem.npy`` (float32 (H, W, 3))."""
    n = np.asarray(normals, dtype=np.float32)
    png = stem.with_suffix(".png")
    enc = np.clip(np.round((n + 1.0) * 0.5 * 65535.0), 0, 65535).astype(np.uint16)
    if not cv2.imwrite(str(png), enc[..., ::-1]):
        raise ReconstructionError(f"could not write {png}")
    npy = stem.with_suffix(".npy")
    np.save(npy, n)
    return [png, npy]


def write_albedo(stem: Path, albedo: NDArray[Any], white: float = 1.0) -> list[Path]:
    """``stem.png`` (16-bit, linear, white = ``white``) and ``stem.npy`` (float32)."""
    a = np.asarray(albedo, dtype=np.float32)
    png = stem.with_suffix(".png")
    enc = np.clip(np.round(a / white * 65535.0), 0, 65535).astype(np.uint16)
    if not cv2.imwrite(str(png), enc[..., ::-1] if enc.ndim == 3 else enc):
        raise ReconstructionError(f"could not write {png}")
    npy = stem.with_suffix(".npy")
    np.save(npy, a)
    return [png, npy]
