"""Small synthetic scenes with known answers, for tests and the fit-throughput benchmark.

Not the project's simulator (that lives in ``simulator/``): just closed-form normals and a
Lambertian-plus-Blinn–Phong shader, enough to know what a fit must return.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray


def fibonacci_lights(n: int, min_elevation_deg: float = 10.0) -> NDArray[np.float64]:
    """``n`` unit lights spread evenly over the hemisphere above ``min_elevation_deg``."""
    i = np.arange(n) + 0.5
    zmin = np.sin(np.radians(min_elevation_deg))
    z = 1.0 - (1.0 - zmin) * i / n
    r = np.sqrt(1.0 - z * z)
    phi = i * np.pi * (3.0 - np.sqrt(5.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def sphere_normals(
    height: int, width: int, radius_fraction: float = 0.45
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Normals (H, W, 3) of a sphere seen from +z (docs/conventions.md frame, y up) and its mask.

    Outside the sphere the normal is (0, 0, 1), a flat background.
    """
    rows, cols = np.mgrid[0:height, 0:width].astype(np.float64)
    rad = radius_fraction * min(height, width)
    x = (cols - (width - 1) / 2.0) / rad
    y = ((height - 1) / 2.0 - rows) / rad
    rr = x * x + y * y
    inside = rr < 0.98
    z = np.sqrt(np.clip(1.0 - rr, 0.0, 1.0))
    n = np.stack([np.where(inside, x, 0.0), np.where(inside, y, 0.0), np.where(inside, z, 1.0)], -1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True), inside


def render(
    normals: NDArray[np.float64],
    albedo: NDArray[np.float64] | float,
    lights: NDArray[np.float64],
    specular: float = 0.0,
    shininess: float = 50.0,
) -> NDArray[np.float32]:
    """Images (N, H, W) or (N, H, W, C) if ``albedo`` has a channel axis.

    ``rho * max(0, n.l) + specular * max(0, n.h)^shininess`` (Blinn–Phong, viewer on +z,
    highlight white), with attached shadows and no cast shadows.
    """
    shade = np.maximum(np.einsum("hwk,nk->nhw", normals, lights), 0.0)
    alb = np.asarray(albedo, dtype=np.float64)
    img = shade[..., None] * alb if alb.ndim == 3 else shade * alb
    if specular > 0:
        half = lights + np.array([0.0, 0.0, 1.0])
        half /= np.linalg.norm(half, axis=1, keepdims=True)
        spec = np.maximum(np.einsum("hwk,nk->nhw", normals, half), 0.0) ** shininess
        spec *= shade > 0
        img = img + specular * (spec[..., None] if alb.ndim == 3 else spec)
    return img.astype(np.float32)


def sphere_frames(
    n: int, side: int, specular: float = 0.0, shininess: float = 50.0
) -> tuple[list[NDArray[np.uint16]], NDArray[np.float64]]:
    """A still, correctly lit grey sphere under ``n`` :func:`fibonacci_lights` (from 15°):
    ``n`` uint16 RGB frames of ``side`` px at 70 % of full scale, a little noise (seeded), and
    the lights. The QA's CPU benchmark (``benchmarks/qa_time.py``) and its memory test time
    and measure the same frames; each had written its own copy of this loop."""
    lights = fibonacci_lights(n, 15.0)
    normals, _ = sphere_normals(side, side, 0.4)
    albedo = np.full((side, side, 3), 0.5)
    rng = np.random.default_rng(0)
    frames = []
    for d in lights:
        img = render(normals, albedo, d[None], specular=specular, shininess=shininess)[0] * 0.7
        img = img + rng.normal(0, 0.002, img.shape)
        frames.append(np.clip(np.round(img * 65535), 0, 65535).astype(np.uint16))
    return frames, lights


def _changed_session_copy(
    session: Path, dst: Path, first: int, change: Callable[[NDArray], NDArray]
) -> Path:
    """A copy of ``session`` whose linear images from ``first`` (1-based) on are ``change``d:
    what the object or camera did once, part-way through."""
    import shutil

    from rti_rig.core.image_files import read_linear_tiff, write_linear_tiff

    shutil.copytree(session, dst)
    for f in sorted((dst / "linear").glob("image_*.tif"))[first - 1 :]:
        img = read_linear_tiff(f)
        f.unlink()
        write_linear_tiff(f, change(img))
    return dst


def moved_session_copy(session: Path, dst: Path, first: int, dx: int, dy: int) -> Path:
    """A copy of ``session`` whose images from ``first`` (1-based) on are shifted by
    ``(dx, dy)`` px (x right, y down): the object nudged once, part-way through. Here, not in
    tests/, so that benchmarks/qa_step_margin.py measures the same move the QA tests claim."""
    return _changed_session_copy(
        session, dst, first, lambda img: np.roll(img, (dy, dx), axis=(0, 1))
    )


def turned_session_copy(session: Path, dst: Path, first: int, angle_deg: float) -> Path:
    """A copy of ``session`` whose images from ``first`` (1-based) on are turned by
    ``angle_deg`` (counter-clockwise as seen) about the frame's centre: a camera knocked once,
    part-way through, rolling about its axis. Here, not in tests/, so that
    benchmarks/qa_turn.py turns a session the same way the QA tests do."""
    import cv2

    def turned(img: NDArray) -> NDArray:
        h, w = img.shape[:2]
        m = cv2.getRotationMatrix2D((w / 2, h / 2), angle_deg, 1.0)
        out = cv2.warpAffine(
            img, m, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
        )
        return out.reshape(img.shape).astype(img.dtype)

    return _changed_session_copy(session, dst, first, turned)


def camera_bits_copy(
    session: Path,
    dst: Path,
    gain: float,
    bits: int = 12,
    shift: int = 0,
    icc: bytes | None = None,
) -> Path:
    """``session``'s linear images as a ``bits``-bit camera stores them in 16-bit TIFFs: at
    ``gain`` × its exposure, clipped at the depth's top, shifted up by ``shift`` bits (with the
    ICC profile ``icc``), and a lights.lp naming them — an acquisition from elsewhere (no
    session record beside it). Here, not in tests/, so that benchmarks/full_scale.py measures
    the files the fit tests read."""
    import tifffile

    from rti_rig.core.image_files import read_linear_tiff

    dst.mkdir()
    top = (1 << bits) - 1
    lines = (session / "lights.lp").read_text(encoding="utf-8").splitlines()
    listed = [lines[0]]
    for line in lines[1:]:
        name, *xyz = line.split()
        stem = Path(name).stem
        linear = read_linear_tiff(session / "linear" / f"{stem}.tif").astype(np.float64)
        codes = np.clip(np.round(linear / 65535 * gain * top), 0, top).astype(np.uint32)
        tifffile.imwrite(dst / f"{stem}.tif", (codes << shift).astype(np.uint16), iccprofile=icc)
        listed.append(" ".join([f"{stem}.tif", *xyz]))
    (dst / "lights.lp").write_text("\n".join(listed) + "\n", encoding="utf-8")
    return dst
