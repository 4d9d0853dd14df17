"""Accuracy metrics of reconstructions: normals and relighting.

* **Angular error** of normals in degrees, ``atan2(|a × b|, a · b)`` on renormalised vectors
  (accurate for tiny angles, unlike ``acos``): mean, median and 90th percentile over a mask.
* **Normal-map PSNR / SSIM** (the metrics of the planning paper this project grew from): the
  normal map is encoded as an image the usual way, ``(n + 1) / 2`` per component, so each
  channel lies in [0, 1] and the **data range is 1**. PSNR uses the MSE over the three channels
  of the masked pixels; SSIM is computed per channel and averaged.
* **Relighting PSNR / SSIM** on lights *not used for fitting*: each held-out image is compared
  with the model's relighting under its light, per light, and the mean over lights is reported
  (the leave-out protocol of Pintus et al. 2018). Linear images have no fixed white, so the
  data range is an argument: pass the sensor's saturation level in the images' units
  (1.0 for frames scaled by :func:`rti_rig.reconstruct.stack_from_frames`). The default, 1.0,
  is that.
* **SSIM** (Wang, Bovik, Sheikh, Simoncelli 2004): Gaussian window σ = 1.5 truncated at radius
  5 (11 × 11), K1 = 0.01, K2 = 0.03, local statistics by ``scipy.ndimage.gaussian_filter``
  (population covariance, as in the paper's Gaussian variant). The mean is taken over pixels at
  least 5 from the border (where the window is complete) and inside the mask, if one is given.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.ndimage import gaussian_filter

from rti_rig.reconstruct.stack import ImageStack, validate_lights

SSIM_SIGMA = 1.5
SSIM_RADIUS = 5
SSIM_K1 = 0.01
SSIM_K2 = 0.03
#: PSNR reported for identical images (the MSE is zero): a finite cap keeps tables printable.
PSNR_CAP_DB = 100.0


@dataclass(frozen=True)
class AngularErrorStats:
    """Angular error of normals over the compared pixels, in degrees."""

    mean: float
    median: float
    p90: float
    count: int


def _mask(mask: ArrayLike | None, shape: tuple[int, ...]) -> NDArray[np.bool_]:
    if mask is None:
        return np.ones(shape, dtype=bool)
    m = np.asarray(mask, dtype=bool)
    if m.shape != shape:
        raise ValueError(f"mask has shape {m.shape}, expected {shape}")
    if not m.any():
        raise ValueError("mask selects no pixel")
    return m


def angular_error_map(n_est: ArrayLike, n_true: ArrayLike) -> NDArray[np.float64]:
    """Per-pixel angle (H, W) in degrees between normal maps (H, W, 3); NaN where a normal is 0."""
    a = np.asarray(n_est, dtype=np.float64)
    b = np.asarray(n_true, dtype=np.float64)
    if a.shape != b.shape or a.shape[-1] != 3:
        raise ValueError(f"normal maps must both be (H, W, 3), got {a.shape} and {b.shape}")
    na = np.linalg.norm(a, axis=-1)
    nb = np.linalg.norm(b, axis=-1)
    cross = np.linalg.norm(np.cross(a, b), axis=-1)
    dot = np.sum(a * b, axis=-1)
    ang = np.degrees(np.arctan2(cross, dot))
    return np.where((na > 0) & (nb > 0), ang, np.nan)


def angular_error_deg(
    n_est: ArrayLike, n_true: ArrayLike, mask: ArrayLike | None = None
) -> AngularErrorStats:
    """Mean, median and 90th percentile of the angle between normal maps over ``mask``.

    A zero normal inside the mask is an error (it has no direction): mask it out explicitly.
    """
    ang = angular_error_map(n_est, n_true)
    m = _mask(mask, ang.shape)
    vals = ang[m]
    if np.any(np.isnan(vals)):
        raise ValueError("a normal inside the mask has zero length; exclude it with the mask")
    return AngularErrorStats(
        mean=float(vals.mean()),
        median=float(np.median(vals)),
        p90=float(np.percentile(vals, 90)),
        count=int(vals.size),
    )


def psnr(
    estimate: ArrayLike, reference: ArrayLike, data_range: float, mask: ArrayLike | None = None
) -> float:
    """PSNR in dB of ``estimate`` against ``reference`` (H, W[, C]) over ``mask`` (H, W)."""
    a = np.asarray(estimate, dtype=np.float64)
    b = np.asarray(reference, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(f"shapes differ: {a.shape} vs {b.shape}")
    if data_range <= 0:
        raise ValueError(f"data_range must be positive, got {data_range}")
    m = _mask(mask, b.shape[:2])
    mse = float(np.mean((a[m] - b[m]) ** 2))
    if mse == 0:
        return PSNR_CAP_DB
    return float(min(PSNR_CAP_DB, 10.0 * np.log10(data_range**2 / mse)))


def ssim_map(a: NDArray[np.float64], b: NDArray[np.float64], data_range: float) -> NDArray:
    """Local SSIM (H, W) of two single-channel images (Gaussian window, see module doc)."""
    c1 = (SSIM_K1 * data_range) ** 2
    c2 = (SSIM_K2 * data_range) ** 2
    truncate = SSIM_RADIUS / SSIM_SIGMA

    def blur(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return gaussian_filter(x, SSIM_SIGMA, truncate=truncate, mode="reflect")

    mu_a, mu_b = blur(a), blur(b)
    var_a = blur(a * a) - mu_a * mu_a
    var_b = blur(b * b) - mu_b * mu_b
    cov = blur(a * b) - mu_a * mu_b
    num = (2 * mu_a * mu_b + c1) * (2 * cov + c2)
    den = (mu_a * mu_a + mu_b * mu_b + c1) * (var_a + var_b + c2)
    return num / den


def ssim(
    estimate: ArrayLike, reference: ArrayLike, data_range: float, mask: ArrayLike | None = None
) -> float:
    """Mean SSIM of images (H, W[, C]), channels averaged, over full windows inside ``mask``."""
    a = np.asarray(estimate, dtype=np.float64)
    b = np.asarray(reference, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(f"shapes differ: {a.shape} vs {b.shape}")
    if data_range <= 0:
        raise ValueError(f"data_range must be positive, got {data_range}")
    h, w = b.shape[:2]
    if h <= 2 * SSIM_RADIUS or w <= 2 * SSIM_RADIUS:
        raise ValueError(f"SSIM needs images larger than {2 * SSIM_RADIUS + 1} pixels a side")
    m = _mask(mask, (h, w)).copy()
    m[:SSIM_RADIUS] = m[-SSIM_RADIUS:] = False
    m[:, :SSIM_RADIUS] = m[:, -SSIM_RADIUS:] = False
    if not m.any():
        raise ValueError("mask selects no pixel away from the border")
    if a.ndim == 2:
        a, b = a[..., None], b[..., None]
    maps = [ssim_map(a[..., c], b[..., c], data_range)[m] for c in range(a.shape[-1])]
    return float(np.mean(maps))


def encode_normals(normals: ArrayLike) -> NDArray[np.float64]:
    """Normal map (H, W, 3) as an image in [0, 1]: ``(n + 1) / 2``."""
    return (np.asarray(normals, dtype=np.float64) + 1.0) / 2.0


def normal_map_psnr(n_est: ArrayLike, n_true: ArrayLike, mask: ArrayLike | None = None) -> float:
    """PSNR (dB) of encoded normal maps, data range 1."""
    return psnr(encode_normals(n_est), encode_normals(n_true), 1.0, mask)


def normal_map_ssim(n_est: ArrayLike, n_true: ArrayLike, mask: ArrayLike | None = None) -> float:
    """SSIM of encoded normal maps, data range 1, averaged over x, y, z channels."""
    return ssim(encode_normals(n_est), encode_normals(n_true), 1.0, mask)


def _per_light(
    metric: Any, model: Any, images: Any, lights: ArrayLike, data_range: float, mask: Any
) -> NDArray[np.float64]:
    stack = ImageStack(images)
    lt = validate_lights(lights, stack.n)
    out = np.empty(stack.n)
    full = slice(0, stack.height)
    for i in range(stack.n):
        ref = stack.rows(full, [i])[0]
        if stack.grey:
            ref = ref[..., 0]
        out[i] = metric(model.relight(lt[i]), ref, data_range, mask)
    return out


def relight_psnr_per_light(
    model: Any, images: Any, lights: ArrayLike, data_range: float = 1.0, mask: Any = None
) -> NDArray[np.float64]:
    """PSNR (dB) of ``model.relight(l_i)`` against each held-out image i."""
    return _per_light(psnr, model, images, lights, data_range, mask)


def relight_ssim_per_light(
    model: Any, images: Any, lights: ArrayLike, data_range: float = 1.0, mask: Any = None
) -> NDArray[np.float64]:
    """SSIM of ``model.relight(l_i)`` against each held-out image i."""
    return _per_light(ssim, model, images, lights, data_range, mask)


def relight_psnr(
    model: Any, images: Any, lights: ArrayLike, data_range: float = 1.0, mask: Any = None
) -> float:
    """Mean over held-out lights of relighting PSNR (dB); ``images`` were not used to fit."""
    return float(np.mean(relight_psnr_per_light(model, images, lights, data_range, mask)))


def relight_ssim(
    model: Any, images: Any, lights: ArrayLike, data_range: float = 1.0, mask: Any = None
) -> float:
    """Mean over held-out lights of relighting SSIM; ``images`` were not used to fit."""
    return float(np.mean(relight_ssim_per_light(model, images, lights, data_range, mask)))


@dataclass(frozen=True)
class ReconstructionScores:
    """Every metric that applies to one fitted model; None where it does not apply.

    ``valid_fraction`` is the share of the compared pixels where the model gave a normal
    (photometric stereo marks some invalid); angular and normal-map scores are over those.
    """

    model: str
    n_coefficients: int
    angular: AngularErrorStats | None
    normal_psnr: float | None
    normal_ssim: float | None
    valid_fraction: float | None
    relight_psnr: float | None
    relight_ssim: float | None


def model_normals(model: Any) -> tuple[NDArray[np.float32], NDArray[np.bool_] | None] | None:
    """Normals a model provides and its validity mask: PS result, Lambert, PTM; else None."""
    normals = getattr(model, "normals", None)
    if normals is None:
        return None
    if callable(normals):
        return normals(), None
    return normals, getattr(model, "valid", None)


def score_reconstruction(
    model: Any,
    *,
    true_normals: ArrayLike | None = None,
    mask: ArrayLike | None = None,
    held_images: Any = None,
    held_lights: ArrayLike | None = None,
    data_range: float = 1.0,
) -> ReconstructionScores:
    """Score a fitted model against ground-truth normals and/or held-out images.

    The entry point for speed/accuracy comparisons: one call per (plan, model). Normal metrics
    are computed where ``true_normals`` is given and the model has normals (HSH has none);
    relighting metrics where held-out images and their lights are given.
    """
    angular = n_psnr = n_ssim = valid_fraction = None
    got = model_normals(model)
    if true_normals is not None and got is not None:
        est, valid = got
        truth = np.asarray(true_normals, dtype=np.float64)
        region = _mask(mask, truth.shape[:2])
        usable = region if valid is None else region & valid
        valid_fraction = float(usable.sum() / region.sum())
        if usable.any():
            angular = angular_error_deg(est, truth, usable)
            n_psnr = normal_map_psnr(est, truth, usable)
            n_ssim = normal_map_ssim(est, truth, usable)
    r_psnr = r_ssim = None
    if held_images is not None and held_lights is not None:
        r_psnr = relight_psnr(model, held_images, held_lights, data_range, mask)
        r_ssim = relight_ssim(model, held_images, held_lights, data_range, mask)
    return ReconstructionScores(
        model=str(model.name),
        n_coefficients=int(model.n_coefficients),
        angular=angular,
        normal_psnr=n_psnr,
        normal_ssim=n_ssim,
        valid_fraction=valid_fraction,
        relight_psnr=r_psnr,
        relight_ssim=r_ssim,
    )
