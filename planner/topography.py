"""Topography from one preview shot: linearise, downsample, find the light, recover relief.

Three routes lead from a preview photo to a relief (a height field up to an unknown scale), which
:mod:`rti_rig.planner.normals` turns into normals:

* :func:`depth_from_onnx` runs a monocular depth network the user supplies (MiDaS / DPT / Depth
  Anything output relative *inverse* depth, "bright = near"; LeReS outputs affine-invariant
  *depth*), through onnxruntime on the CPU. No weights ship with rti-rig: none is redistributable
  offline (see the algorithms notes, section 5), and networks trained on scenes see little of a
  bas-relief anyway.
* :func:`shape_from_shading` is the weight-free default: Pentland's linear shape from shading
  (one FFT) when the preview's light is oblique, and a second-order shading model when it is near
  the zenith (where the first-order term vanishes and Pentland divides by ``sin(slant) ≈ 0``).
* :func:`estimate_light` recovers the preview's light from image statistics
  (Zheng & Chellappa 1991) when the user does not give ``--preview-light``.

Assumptions about the preview (what :func:`linear_luminance` converts): ``uint8`` is sRGB and is
linearised with the sRGB transfer curve; ``uint16`` and floating point are already linear
(RAW decoded with gamma 1, docs/conventions.md "Linear data"); ``uint16`` is scaled by 65535
and floats are used as they are. A preview file that says another space (Adobe RGB, ProPhoto,
Display P3) or is 16-bit sRGB-encoded reaches here already converted to linear sRGB ``uint16``:
the plan's use case converts it (:func:`rti_rig.app.usecases.plan.preview_in_its_space`, the
camera drivers' conversion, which the planner may not import). Colour is reduced to Rec. 709
luminance. Everything downstream works on a preview downsampled early to at most
:data:`PLANNING_SIDE_PX` pixels on its long side: planning needs the distribution of normals,
not their detail, and a 24-megapixel preview would otherwise cost seconds.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import cv2
import numpy as np
from numpy.typing import NDArray

from rti_rig.core import opencv_files
from rti_rig.core.errors import ConfigError, ScheduleError
from rti_rig.core.geometry import direction_from_az_el, normalize
from rti_rig.core.image_files import (
    SeveralFullSizeImages,
    colour_or_grey,
    is_tiff_file,
    jpeg_truncation,
    opencv_as_stored,
    tiff_is_planar,
    tiff_one_image,
    tiff_samples_last,
)
from rti_rig.core.shell_words import shown_path

#: Long side, in pixels, of the image the planner works on.
PLANNING_SIDE_PX = 256

#: Below this slant (degrees from the camera axis) the light counts as "from the zenith".
ZENITH_SLANT_DEG = 12.0

REC709 = np.array([0.2126, 0.7152, 0.0722])


def _srgb_to_linear(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def linear_luminance(preview: NDArray) -> NDArray[np.float64]:
    """Linear luminance (H, W) in [0, 1] of a preview (H, W) or (H, W, 3|4); see module notes."""
    img = np.asarray(preview)
    if img.ndim == 3 and img.shape[2] in (3, 4):
        img = img[..., :3]
    elif img.ndim != 2:
        raise ScheduleError(
            f"the preview must be an image (H, W) or (H, W, 3), got an array of shape {img.shape}"
        )
    if img.shape[0] < 1 or img.shape[1] < 1:
        raise ScheduleError(f"the preview is empty (shape {img.shape})")
    if img.dtype == np.uint8:
        lin = _srgb_to_linear(img.astype(np.float64) / 255.0)
    elif img.dtype == np.uint16:
        lin = img.astype(np.float64) / 65535.0
    elif np.issubdtype(img.dtype, np.floating):
        lin = img.astype(np.float64)
        if not np.all(np.isfinite(lin)):
            raise ScheduleError("the preview contains NaN or infinite pixels; give a clean image")
        lin = np.clip(lin, 0.0, None)
    else:
        raise ScheduleError(
            f"preview pixels of type {img.dtype} are not supported; use uint8 sRGB, "
            "uint16 linear or float linear"
        )
    if lin.ndim == 3:
        lin = lin @ REC709
    return lin


def read_preview(path: Path) -> NDArray:
    """The preview image file as an array in RGB order, keeping its type (the CLI's edge).

    8-bit files (JPEG, PNG) are taken as sRGB; 16-bit files (TIFF, PNG) as linear data, which
    is what ``rti-rig run`` writes for fitting (docs/conventions.md "Linear data").
    """
    p = Path(path)
    if p.is_dir():
        raise ScheduleError(f"{shown_path(p)} is a folder: give one preview image file")
    if not p.is_file():
        raise ScheduleError(f"{shown_path(p)}: preview image not found")
    why = jpeg_truncation(p)  # OpenCV decodes a cut-short JPEG, its missing part grey
    if why is not None:
        raise ScheduleError(
            f"{shown_path(p)}: damaged JPEG: {why}; copy it again from the camera or card"
        )
    tiff = _read_tiff_preview(p)
    if tiff is not None:
        return tiff
    img = opencv_files.imread(p)
    if img is None:
        raise ScheduleError(
            f"{shown_path(p)}: cannot read this file as an image (JPEG, PNG or TIFF)"
        )
    # grey + alpha is grey, an alpha dropped, as the replay rig and the fit read it: a grey
    # camera's grey + alpha PNG had been read as colour
    return opencv_as_stored(img, p)


def _read_tiff_preview(p: Path) -> NDArray | None:
    """A TIFF preview's full-resolution image in RGB order, its type kept; None when ``p`` is
    no TIFF or tifffile cannot read it (OpenCV then tries, and names the failure).

    Why not OpenCV: it reads IFD0, and some cameras and tethering programs put a small
    thumbnail there, the photograph in a later IFD or a SubIFD: the plan had been made from
    the thumbnail. :func:`~rti_rig.core.image_files.tiff_main_image` picks the image, as the
    replay rig and the watched folder do."""
    if not is_tiff_file(p):
        return None
    import tifffile  # on a TIFF only: planning from a JPEG never needs it

    try:
        with tifffile.TiffFile(p) as tif:
            image = tiff_one_image(tif)  # not a thumbnail, nor one page of a stack
            pixels = tiff_samples_last(image.asarray(), tiff_is_planar(image.keyframe))
    except SeveralFullSizeImages as exc:
        raise ScheduleError(f"preview {shown_path(p)}: {exc}") from None
    except Exception:  # tifffile raises many kinds for a damaged file; OpenCV's turn
        return None
    return np.ascontiguousarray(colour_or_grey(pixels))


def downsample(image: NDArray[np.float64], max_side: int = PLANNING_SIDE_PX) -> NDArray:
    """Area-averaged copy with the long side at most ``max_side`` (tiny images are kept)."""
    h, w = image.shape[:2]
    f = max_side / max(h, w)
    if f >= 1.0:
        return image.astype(np.float64)
    size = (max(1, round(w * f)), max(1, round(h * f)))
    return cv2.resize(image.astype(np.float32), size, interpolation=cv2.INTER_AREA).astype(
        np.float64
    )


def planning_image(preview: NDArray, max_side: int = PLANNING_SIDE_PX) -> NDArray[np.float64]:
    """The preview as the planner sees it: downsampled first (cheap on 24 MP), then linearised.

    Downsampling an sRGB image before linearising averages gamma-encoded values, which biases
    the mean slightly low; for planning that is irrelevant next to the cost saved on 24 MP.
    """
    img = np.asarray(preview)
    if img.ndim >= 2 and max(img.shape[:2]) > max_side:
        f = max_side / max(img.shape[:2])
        size = (max(1, round(img.shape[1] * f)), max(1, round(img.shape[0] * f)))
        if img.dtype in (np.uint8, np.uint16):
            img = cv2.resize(img, size, interpolation=cv2.INTER_AREA)
        elif np.issubdtype(img.dtype, np.floating) and np.all(np.isfinite(img)):
            img = cv2.resize(img.astype(np.float32), size, interpolation=cv2.INTER_AREA)
    return downsample(linear_luminance(img), max_side)


@dataclass(frozen=True)
class LightEstimate:
    """The preview's light direction and how it was obtained ("given" or "estimated")."""

    direction: NDArray[np.float64]
    source: str
    albedo: float
    #: Why no direction could be read from the image, when the zenith was assumed instead
    #: (None: estimated). Why kept: the zenith had been reported as "estimated", az 0°, el 90°,
    #: as if the image had said so.
    why_zenith: str | None = None


def estimate_light(image: NDArray[np.float64]) -> LightEstimate:
    """Zheng & Chellappa (1991) light direction and albedo from image statistics.

    With mean ``mu1`` and mean square ``mu2`` of the shading, ``g = sqrt(6 pi^2 mu2 - 48 mu1^2)``,
    albedo ``g / pi``, slant ``arccos(4 mu1 / g)``; the tilt is the direction of the mean unit
    image gradient (in the frame of docs/conventions.md: rows run down, so the row derivative
    flips sign).
    Where the image gives no direction the zenith is assumed, the least committal answer, and
    ``why_zenith`` says why: degenerate images (constant, black), shading that varies too
    little for any slanted light (``4 mu1 / g > 1``: the slant's cosine above 1, clipped), or
    no gradient to give the tilt.
    """
    zenith = np.array([0.0, 0.0, 1.0])
    e = image / max(float(image.max()), 1e-12)
    mu1, mu2 = float(e.mean()), float((e * e).mean())
    g2 = 6 * np.pi**2 * mu2 - 48 * mu1**2
    if g2 <= 1e-12 or mu1 <= 0:
        why = "its shading is uniform or black"
        return LightEstimate(zenith, "assumed", float(image.max()), why)
    g = np.sqrt(g2)
    cos_slant = 4 * mu1 / g
    if cos_slant > 1.0:
        why = (
            f"its shading varies too little for any slanted light (4μ1/g = {cos_slant:.2f} > "
            "1: Zheng & Chellappa's slant has no solution)"
        )
        return LightEstimate(zenith, "assumed", float(g / np.pi * image.max()), why)
    slant = float(np.arccos(np.clip(cos_slant, -1.0, 1.0)))
    if image.shape[0] > 1 and image.shape[1] > 1:
        gr, gc = np.gradient(e)
    else:
        gr = gc = np.zeros_like(e)
    gx, gy = gc, -gr
    mag = np.hypot(gx, gy)
    ok = mag > 1e-9
    if np.count_nonzero(ok) == 0:
        why = "it has no shading gradient to give the light's azimuth"
        return LightEstimate(zenith, "assumed", float(g / np.pi * image.max()), why)
    tilt = float(np.arctan2((gy[ok] / mag[ok]).mean(), (gx[ok] / mag[ok]).mean()))
    d = np.array([np.cos(tilt) * np.sin(slant), np.sin(tilt) * np.sin(slant), np.cos(slant)])
    return LightEstimate(normalize(d), "estimated", float(g / np.pi * image.max()))


def given_light(az_el_deg: tuple[float, float]) -> NDArray[np.float64]:
    """Direction of ``--preview-light AZ,EL`` (degrees, frame of docs/conventions.md), validated."""
    az, el = (float(v) for v in az_el_deg)
    if not (np.isfinite(az) and np.isfinite(el)) or not 0.0 < el <= 90.0:
        raise ScheduleError(
            f"--preview-light elevation must be in (0, 90] degrees, got {el:g} "
            "(a light at or below the object plane does not light it)"
        )
    return direction_from_az_el(az, el)


def _frankot_chellappa(p: NDArray, q: NDArray) -> NDArray[np.float64]:
    """Least-squares integrable height from gradients p = dh/dx, q = dh/dy (y up) by FFT."""
    h, w = p.shape
    # rows run down: dh/drow = -q
    wx = np.fft.fftfreq(w) * 2 * np.pi
    wr = np.fft.fftfreq(h) * 2 * np.pi
    ux, ur = np.meshgrid(wx, wr)
    denom = ux**2 + ur**2
    denom[0, 0] = 1.0
    fz = (-1j * ux * np.fft.fft2(p) - 1j * ur * np.fft.fft2(-q)) / denom
    fz[0, 0] = 0.0
    return np.real(np.fft.ifft2(fz))


def shape_from_shading(
    image: NDArray[np.float64], light: NDArray[np.float64], albedo: float | None = None
) -> NDArray[np.float64]:
    """A relief (height, arbitrary scale) explaining the preview's shading under ``light``.

    Oblique light — Pentland (1990) linear SfS: ``E ≈ ρ (l_z - l_x p - l_y q)`` (Lambertian
    linearised about the flat surface, ``p, q`` the height slopes), so in Fourier space the
    height is the shading divided by ``-i (ω·t) sin σ``; frequencies orthogonal to the light's
    tilt ``t`` carry no information and are zeroed (the known blind spot of a single raking
    light; the scale is refitted from evidence in :mod:`rti_rig.planner.normals`).

    Near-zenith light — the first-order term vanishes; to second order
    ``E ≈ ρ (1 - |∇h|² / 2)``, which gives the slope magnitude, and the height is taken to rise
    along the shading gradient (a bump under a zenith light is brightest at its top; the
    convex/concave ambiguity is resolved towards convex), then
    the gradient field is integrated by Frankot & Chellappa (1988).
    """
    h, w = image.shape
    if h < 2 or w < 2:
        return np.zeros_like(image, dtype=np.float64)
    rho = float(albedo) if albedo else float(np.percentile(image, 99.5))
    if rho <= 1e-12:
        return np.zeros_like(image, dtype=np.float64)
    lx, ly, lz = (float(v) for v in normalize(light))
    slant = np.degrees(np.arccos(np.clip(lz, -1, 1)))
    e = np.clip(image / rho, 0.0, 1.5)
    if slant >= ZENITH_SLANT_DEG:
        sin_s = np.hypot(lx, ly)
        tx, ty = lx / sin_s, ly / sin_s
        wx = np.fft.fftfreq(w) * 2 * np.pi
        wy = -np.fft.fftfreq(h) * 2 * np.pi  # frame y is up, rows run down
        ux, uy = np.meshgrid(wx, wy)
        proj = ux * tx + uy * ty
        fe = np.fft.fft2(e - e.mean())
        ok = np.abs(proj) > 1e-3 * np.pi
        fz = np.zeros_like(fe)
        # E - mean = -sin(s) (t · ∇h)  →  F_E = -sin(s) · i (ω·t) F_h
        fz[ok] = fe[ok] / (-1j * proj[ok] * sin_s)
        # damp the near-singular band so noise does not explode into long ridges
        fz *= np.abs(proj) ** 2 / (np.abs(proj) ** 2 + (0.05 * np.pi) ** 2)
        return np.real(np.fft.ifft2(fz))
    slope = np.sqrt(np.clip(2.0 * (1.0 - e / max(lz, 1e-6)), 0.0, None))
    gr, gc = np.gradient(cv2.GaussianBlur(e.astype(np.float32), (0, 0), 1.0).astype(np.float64))
    gx, gy = gc, -gr
    mag = np.hypot(gx, gy)
    safe = np.where(mag > 1e-9, mag, 1.0)
    p = np.where(mag > 1e-9, slope * gx / safe, 0.0)
    q = np.where(mag > 1e-9, slope * gy / safe, 0.0)
    return _frankot_chellappa(p, q)


DepthKind = Literal["inverse_depth", "depth"]


@dataclass(frozen=True)
class DepthModelSpec:
    """How to feed and read a monocular depth network exported to ONNX.

    Defaults follow MiDaS v2.1 small (256×256, ImageNet mean/std, relative inverse depth).
    Depth Anything V2: ``input_size=(518, 518)``; LeReS: ``(448, 448)``, ``output="depth"``.
    ``mean``/``std`` are applied to RGB in [0, 1]; set them to (0,0,0)/(1,1,1) for graphs that
    normalise internally (the official MiDaS ONNX export does).
    """

    input_size: tuple[int, int] = (256, 256)
    mean: tuple[float, float, float] = (0.485, 0.456, 0.406)
    std: tuple[float, float, float] = (0.229, 0.224, 0.225)
    output: DepthKind = "inverse_depth"


def _rgb01(preview: NDArray) -> NDArray[np.float32]:
    """The preview as display-referred RGB in [0, 1] (what depth networks were trained on)."""
    img = np.asarray(preview)
    if img.ndim == 2:
        img = np.repeat(img[..., None], 3, axis=2)
    img = img[..., :3]
    if img.dtype == np.uint8:
        return img.astype(np.float32) / 255.0
    if img.dtype == np.uint16:
        lin = img.astype(np.float32) / 65535.0
    else:
        lin = np.clip(np.nan_to_num(img.astype(np.float32)), 0.0, None)
        lin = lin / max(float(lin.max()), 1e-12)
    # networks expect gamma-encoded photos: encode linear data with the sRGB curve
    lin = np.clip(lin, 0.0, 1.0)
    return np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * lin ** (1 / 2.4) - 0.055).astype(
        np.float32
    )


def _declared_size(shape: list[object]) -> tuple[int, int]:
    """The (H, W) a model's image input declares (N, C, H, W) where both are fixed numbers,
    else MiDaS v2.1 small's 256×256.

    Why: ``plan --depth-model`` has no option for the input size, and a Depth Anything export
    (518×518) or a MiDaS at 384×384 was refused with "check input_size", a setting the command
    line does not offer; the model says its size itself."""
    if len(shape) == 4:
        h, w = shape[2], shape[3]
        if isinstance(h, int) and isinstance(w, int) and h > 0 and w > 0:
            return h, w
    return DepthModelSpec().input_size


def depth_from_onnx(
    preview: NDArray,
    model_path: Path,
    spec: DepthModelSpec | None = None,
    out_shape: tuple[int, int] | None = None,
) -> NDArray[np.float64]:
    """Relief (height, larger = nearer the camera) from a monocular depth network in ONNX.

    The preview is resized to the model's input, normalised and fed as NCHW float32; the first
    output (N,H,W), (N,1,H,W) or (H,W) is resized to ``out_shape`` (default the preview's). An
    inverse-depth output is already "larger = nearer" and is used as the height; a depth output is
    negated. Non-finite outputs are kept as NaN for :mod:`rti_rig.planner.normals` to handle.
    """
    import onnxruntime as ort

    given = spec is not None
    path = Path(model_path)
    if not path.is_file():
        raise ConfigError(path, None, "depth model file not found; pass an existing .onnx file")
    try:
        session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    except Exception as exc:  # onnxruntime raises its own exception types
        raise ConfigError(path, None, f"onnxruntime cannot load this model: {exc}") from exc
    inputs = session.get_inputs()
    if len(inputs) != 1:
        raise ConfigError(
            path, None, f"expected a model with one image input, it has {len(inputs)}"
        )
    spec = spec or DepthModelSpec(input_size=_declared_size(inputs[0].shape))
    rgb = _rgb01(preview)
    ih, iw = spec.input_size
    x = cv2.resize(rgb, (iw, ih), interpolation=cv2.INTER_AREA)
    x = (x - np.asarray(spec.mean, np.float32)) / np.asarray(spec.std, np.float32)
    x = np.ascontiguousarray(x.transpose(2, 0, 1)[None].astype(np.float32))
    try:
        out = session.run(None, {inputs[0].name: x})[0]
    except Exception as exc:
        declared = "×".join(str(d) for d in inputs[0].shape)
        raise ConfigError(
            path,
            None,
            f"running the model on a 1×3×{ih}×{iw} float32 image failed ({exc}); its input is "
            f"declared {declared} {inputs[0].type}: rti-rig feeds one RGB image, as MiDaS, "
            "Depth Anything and LeReS exports take it" + ("; check input_size" if given else ""),
        ) from exc
    out = np.asarray(out, dtype=np.float64)
    out = out.reshape(out.shape[-2:]) if out.ndim >= 2 and np.prod(out.shape[:-2]) == 1 else out
    if out.ndim != 2:
        raise ConfigError(path, None, f"expected a single depth map output, got shape {out.shape}")
    oh, ow = out_shape or np.asarray(preview).shape[:2]
    finite = np.isfinite(out)
    filled = np.where(finite, out, 0.0).astype(np.float32)
    res = cv2.resize(filled, (ow, oh), interpolation=cv2.INTER_LINEAR).astype(np.float64)
    if not np.all(finite):
        bad = cv2.resize((~finite).astype(np.float32), (ow, oh), interpolation=cv2.INTER_NEAREST)
        res[bad > 0] = np.nan
    return res if spec.output == "inverse_depth" else -res
