"""Per-light intensity (gain) calibration from a level target, and dividing it out.

Photometric stereo, PTM and HSH all assume every light of a session has the same strength.
The LEDs of a real dome do not: on neuralrti-example (72 LEDs) images under some LEDs are
19–37 % darker than the all-light fit predicts, consistently over the whole object, and a
light too dim tilts every normal it helps to fit. A layout's error then depends on which dim
or bright LEDs it happens to take — the "lottery" of docs/research/planner.md.

The calibration here is the usual one for a dome: a matte white card laid level under it,
shot under every light. Its normal is known (``target_normal``, default the zenith), so each
image is gain × albedo × shading with only the gains and the card's albedo (uneven lighting,
dust, texture) unknown: a rank-one product, fitted with medians so a speck or a saturated
patch does not bias it. Gains come out normalised to a median of 1 (the common scale of the
lights cannot be told from the albedo and does not matter to any fit), and the sessions
shot later are divided by them (:func:`apply_light_gains`).

Self-calibration from the object itself (no card) was tried and is not offered: on the
nearly flat, gilded icon it drifted (docs/reconstruction.md, "Light gains").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.reconstruct.errors import ReconstructionError
from rti_rig.reconstruct.stack import ImageStack, as_direction, validate_lights

#: A light is calibrated only where it lights the card at least this fraction of the
#: best-placed lights' shading (the 90th percentile): grazing light on a card is too
#: shadow- and texture-prone to measure.
WELL_LIT_FRACTION = 0.3
#: The card needs at least this many lit pixels in the sample.
MIN_PIXELS = 50
#: A gain this far below the median means a dead LED or a black frame, not a calibration.
MIN_GAIN = 0.05


@dataclass(frozen=True)
class LightGains:
    """Gains of N lights (median 1) and the evidence behind them.

    ``gains`` (N,), or (N, C) for colour images (one gain per light and channel: white LEDs
    differ in colour too); ``estimated`` (N,) False for a light too close to grazing the card
    to measure (its gain is left at 1: calibrate it with a tilted card, or leave it out of
    sessions); ``pixels`` lit card pixels used (fewest over channels); ``passes`` passes run;
    ``last_step`` the largest relative change of a gain in the last pass (how converged).
    """

    gains: NDArray[np.float64]
    estimated: NDArray[np.bool_]
    pixels: int
    passes: int
    last_step: float


def _normalise(gains: NDArray[np.float64], estimated: NDArray[np.bool_]) -> NDArray[np.float64]:
    scale = (
        np.exp(np.median(np.log(np.maximum(gains[estimated], 1e-12)))) if estimated.any() else 1.0
    )
    out = gains / scale
    out[~estimated] = 1.0
    return out


class DeadLightError(ReconstructionError):
    """A light gives almost nothing (:data:`MIN_GAIN`): a dead LED or a black frame.

    ``light`` is its index in the images given (not an LED number) and ``gain`` its measured
    gain. Why a class of its own: the caller knows which LED and which session image that index
    is, and what can be done about it, where this module knows only the position in a stack."""

    def __init__(self, light: int, gain: float) -> None:
        super().__init__(
            f"light {light} gives {gain:.3f} of the median light's signal: a dead LED or a "
            "black frame, not something to calibrate; check that light and drop its image"
        )
        self.light = light
        self.gain = gain


def _check_dead(gains: NDArray[np.float64], estimated: NDArray[np.bool_]) -> None:
    for k in np.flatnonzero(estimated & (gains < MIN_GAIN)):
        raise DeadLightError(int(k), float(gains[k]))


def _target_channel(
    obs: NDArray[np.float32],
    shade: NDArray[np.float64],
    usable: NDArray[np.bool_],
    passes: int,
    tolerance: float,
    min_pixels: int,
) -> tuple[NDArray[np.float64], int, int, float]:
    """Gains of one channel of a level target: obs (N, P) = gain × albedo × shade."""
    # each usable light's image over its shading: gain × albedo, to be factored
    per_light = obs[usable].astype(np.float64) / shade[usable, None]  # (usable, P)
    gains = np.ones(len(shade))
    step, done = np.inf, 0
    bright = np.zeros(obs.shape[1], dtype=bool)
    while done < passes:
        done += 1
        albedo = np.median(per_light / gains[usable, None], axis=0)
        bright = albedo > 0.05 * np.percentile(albedo, 90)
        if int(bright.sum()) < min_pixels:
            raise ReconstructionError(
                f"only {int(bright.sum())} sampled pixels of the target are lit (need "
                f"{min_pixels}): the images are black, or the target does not fill the frame"
            )
        update = np.ones(len(shade))
        update[usable] = np.median(
            per_light[:, bright] / (gains[usable, None] * albedo[bright]), axis=1
        )
        new = _normalise(gains * update, usable)
        step = float(np.max(np.abs(new / gains - 1.0)))
        gains = new
        _check_dead(gains, usable)
        if step < tolerance:
            break
    return gains, int(bright.sum()), done, step


def estimate_light_gains(
    images: Any,
    lights: ArrayLike,
    target_normal: ArrayLike = (0.0, 0.0, 1.0),
    *,
    passes: int = 20,
    tolerance: float = 1e-4,
    min_pixels: int = MIN_PIXELS,
    max_pixels: int = 50_000,
    min_shading: float | None = None,
) -> LightGains:
    """Each light's gain from linear ``images`` (N, H, W[, C]) of a level matte target.

    ``target_normal`` is the card's normal in the frame of docs/conventions.md (the zenith for a
    card lying flat). A light is measured where its shading on the card (cosine of incidence) is at
    least ``min_shading`` — by default :data:`WELL_LIT_FRACTION` of the best-placed lights'
    (their 90th percentile); a calibration that must cover a dome's low ring passes the sine of
    its lowest elevation instead, and accepts that a tilt of the card biases those gains most.
    Reads a regular grid of at most ``max_pixels`` pixels
    (:meth:`ImageStack.pixel_sample`). Raises
    :class:`ReconstructionError` for fewer than 4 lights, images that do not pair with the
    lights, non-finite values, a card too dark to measure, or a light whose gain says its LED is
    dead.
    """
    lt = validate_lights(lights)
    if len(lt) < 4:
        raise ReconstructionError(
            f"light gains need at least 4 lights, got {len(lt)}: calibrate the whole dome at once"
        )
    if passes < 1 or max_pixels < min_pixels:
        raise ReconstructionError(
            f"need passes >= 1 and max_pixels >= min_pixels, got {passes}, {max_pixels}"
        )
    stack = ImageStack(images)
    sample, _ = stack.pixel_sample(max_pixels)  # (N, P, C)
    if sample.shape[0] != len(lt):
        raise ReconstructionError(
            f"{len(lt)} light directions for {sample.shape[0]} images: they must pair one to one"
        )
    if not np.all(np.isfinite(sample)):
        raise ReconstructionError("images hold NaN or infinity; gains need finite linear values")
    shade = np.maximum(lt @ as_direction(target_normal), 0.0)
    if min_shading is None:
        min_shading = WELL_LIT_FRACTION * float(np.percentile(shade, 90))
    elif not 0.0 < min_shading < 1.0:
        raise ReconstructionError(f"min_shading must be in (0, 1), got {min_shading}")
    usable = shade >= min_shading
    if int(usable.sum()) < 4:
        raise ReconstructionError(
            f"only {int(usable.sum())} lights light the card at shading >= {min_shading:.3f}: "
            "need 4; is the card's normal right?"
        )
    results = [
        _target_channel(sample[..., c], shade, usable, passes, tolerance, min_pixels)
        for c in range(sample.shape[-1])
    ]
    gains = np.stack([r[0] for r in results], axis=1)
    return LightGains(
        gains=gains[:, 0] if stack.grey else gains,
        estimated=usable,
        pixels=min(r[1] for r in results),
        passes=max(r[2] for r in results),
        last_step=max(r[3] for r in results),
    )


def apply_light_gains(images: ArrayLike, gains: ArrayLike) -> NDArray[np.float32]:
    """``images`` (N, H, W[, C]) with each light's image divided by its gain (N,) or (N, C).

    Returns a new float32 array; the input (a captured session) is never modified.
    """
    arr = np.asarray(images)
    g = np.asarray(gains, dtype=np.float64)
    if arr.ndim not in (3, 4):
        raise ReconstructionError(
            f"images must have shape (N, H, W) or (N, H, W, C), got {arr.shape}"
        )
    if g.shape[0] != arr.shape[0] or g.ndim > 2:
        raise ReconstructionError(f"{g.shape[0]} gains for {arr.shape[0]} images: one per light")
    if g.ndim == 2 and (arr.ndim != 4 or g.shape[1] != arr.shape[3]):
        raise ReconstructionError(
            f"gains of shape {g.shape} need colour images with {g.shape[1]} channels, "
            f"got images of shape {arr.shape}"
        )
    bad = ~(np.isfinite(g) & (g > 0))
    if bad.any():
        k = int(np.flatnonzero(bad.reshape(len(g), -1).any(axis=1))[0])
        raise ReconstructionError(
            f"gain of light {k} is {g[k].tolist()}: gains must be positive and finite"
        )
    scale = (1.0 / g).reshape((len(g), 1, 1) + ((g.shape[1],) if g.ndim == 2 else ()))
    return arr.astype(np.float32) * scale.astype(np.float32)
