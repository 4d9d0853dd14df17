"""Which images hold no signal: black or clipped throughout, judged on a pixel sample.

Why here and not only in the QA: ``rti-rig fit --no-qa`` wrote normal maps from an
acquisition black throughout (a lens cap, lights that never fired) or saturated throughout
(an exposure far too long) without a word; a least-squares fit of nothing is still a normal
map. This check reads only the pixel sample the model choice and the quantisation ranges
already read (a few hundred thousand values however large the images), so it costs next to
nothing on a 24-MP session.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: A value below this fraction of full scale is black (the QA's "no light" level: the dimmest
#: lit images seen, a glossy coin's low lights metered for its glint, reach 0.13-0.15 %).
BLACK_FRACTION = 0.002
#: An image holds no signal when fewer than this fraction of its sampled values lie between
#: black and saturation (nor fewer than :data:`SIGNAL_MIN_VALUES`). Why not "99 % black or
#: clipped": a small object on black velvet, under 1 % of the frame, was called black in
#: every image. Judged by its brightest values instead, such an image holds signal; a
#: capped lens's few hot pixels (well under 0.1 %) do not.
SIGNAL_SHARE = 0.001
#: The fewest in-range sampled values an image holding signal has, however small the sample.
SIGNAL_MIN_VALUES = 8
#: The pixels sampled from each image: the fit's sample (model choice, quantisation ranges,
#: this check) and the QA's "black throughout", so that both judge the same pixels.
SAMPLE_PIXELS = 30_000
#: Values (pixels × images × channels) the sample holds at most: 30 000 pixels of 100 RGB
#: images (36 MB as float32). The sample is held whole (model choice, quantisation ranges, and
#: the QA's copy of it), so at 30 000 pixels it grew with the lights — 360 MB at 1000 RGB
#: lights, several times that with the copies made from it — while the bands stay within
#: their budget. Up to 100 RGB images the sample is 30 000 pixels, as before.
SAMPLE_VALUES = SAMPLE_PIXELS * 100 * 3
#: The fewest pixels sampled, however many lights (model choice and quantisation ranges are
#: judged on these pixels' observations under every light).
MIN_SAMPLE_PIXELS = 1_000


def sample_pixels(images: int, channels: int) -> int:
    """Pixels the sample of ``images`` images of ``channels`` channels takes: ``SAMPLE_PIXELS``,
    fewer when that many would hold more than ``SAMPLE_VALUES`` values (many lights), so that
    the sample's memory is bounded like a band's rather than growing with the lights."""
    per_pixel = max(1, images * channels)
    return max(MIN_SAMPLE_PIXELS, min(SAMPLE_PIXELS, SAMPLE_VALUES // per_pixel))


def sample_grid(height: int, width: int, max_pixels: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns of the regular grid of at most ``max_pixels`` pixels of a
    ``height`` x ``width`` image: one grid for the stack's pixel sample and the QA's, so that
    ``fit --no-qa`` and the QA judge the same pixels."""
    step = max(1, int(np.ceil(np.sqrt(height * width / max(1, max_pixels)))))
    rows = np.arange(step // 2, height, step)
    cols = np.arange(step // 2, width, step)
    if rows.size == 0:
        rows = np.array([height // 2])
    if cols.size == 0:
        cols = np.array([width // 2])
    return rows, cols


def every_image_black(sample: np.ndarray, saturation_level: float | None) -> bool:
    """Whether every image of ``sample`` (as :func:`images_without_signal`) holds no signal
    and is black: the QA's "black throughout" (a lens cap, lights that never fired), judged by
    the same rule as ``fit --no-qa``'s warning, so that the two cannot disagree."""
    empty = images_without_signal(sample, saturation_level)
    return (
        empty is not None
        and len(empty.indices) == len(sample) > 0
        and all(kind == "black" for kind in empty.kinds)
    )


@dataclass(frozen=True)
class NoSignal:
    """The images that hold no signal, each with what it is (``black``, ``saturated``, or
    ``black or clipped``: a clipped object on a black ground)."""

    indices: tuple[int, ...]
    kinds: tuple[str, ...]


def images_without_signal(sample: np.ndarray, saturation_level: float | None) -> NoSignal | None:
    """The images of ``sample`` (N, P, C: a pixel sample of every image, in the stack's
    scaled units) with almost no value between black and ``saturation_level``
    (:data:`SIGNAL_SHARE`): judged by the values that are lit, not by the share that is dark,
    so a small object on a black ground is signal.

    None where there is no full scale to judge against (float images): "black" means nothing
    without one, and a state not established is not claimed.
    """
    if saturation_level is None or not np.isfinite(saturation_level) or saturation_level <= 0:
        return None
    obs = np.asarray(sample).reshape(len(sample), -1)
    if obs.shape[1] == 0:
        return None
    known = np.isfinite(obs).sum(axis=1)  # NaN (missing) counts as neither black nor signal
    black = (obs < BLACK_FRACTION * saturation_level).sum(axis=1)
    clipped = (obs >= saturation_level).sum(axis=1)
    in_range = known - black - clipped
    need = np.maximum(SIGNAL_MIN_VALUES, SIGNAL_SHARE * known)
    empty = (known > 0) & (in_range < need)
    indices = tuple(int(i) for i in np.flatnonzero(empty))
    kinds = tuple(
        "black"
        if clipped[i] < need[i]
        else "saturated"
        if black[i] < need[i]
        else "black or clipped"
        for i in indices
    )
    return NoSignal(indices, kinds)
