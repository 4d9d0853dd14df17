"""Registration drift between the images of one acquisition, measured without the fit.

Used where it is trustworthy: :func:`edge_shifts_trusted` says whether the images of a session
hold their edges still (an object with albedo texture, like the real acquisition in tests/data:
clean shifts within 0.6 px; the simulated dome's relief, 0.27 px) or not (the tests' 160 x 192
tablet, whose shading edges move with the light: 0.9 px; a glossy coin). Where it is not, the
QA's drift against the fit's prediction is the only measure.

The QA used to measure each image's shift against the fit's prediction. That reference is
corrupted by the very fault it looks for: when the object moves part-way through a session the
fit blends two positions, and a (3, 2) px move from image 21 of 36 was found on image 21 only.
Shading is not a usable reference either (a grazing light's unmodelled shadows moved the peak
by about a pixel).

Here each image is reduced to its **edge strength** (gradient magnitude of the lightly blurred
image, scaled by its own 99th percentile): edges of the relief and the albedo sit in the same
place whatever the light, with a sign and strength that vary, which the magnitude and the scaling
remove. The reference is the per-pixel **median** of those edge images, so it stays where most
images are; each image's shift against it is found by phase correlation (OpenCV's estimate,
computed here so that its peak is searched near no shift: below), the images are moved back
and the median recomputed (a few rounds), so a block of moved images does not drag the
reference. An image is judged only when its edge image correlates with the reference
(the peak's response): a black frame or a featureless image has no position to measure.

The peak is searched **within** :data:`MAX_SHIFT_PX` of no shift. An edge image under one light
shows only the arcs that light brings out, and an object of concentric arcs matches itself far
away: on the emulated domes' glossy coin (256 px) an arc of the rim lit from one side sat
best on the inner ring about 60 px off (OpenCV's ``phaseCorrelate`` takes the highest peak of
the whole image), the next round moved those images back by that much before taking the
median, and by the third round every image's shift was -100 to +95 px: a session that held
still looked chaotic (its edges "not trusted") and an 8 px move from image 31 of 48 went
unseen. Searched near zero, the same session's shifts sit within 1.1 px of their median
(robust spread 0.66 px: still not trusted, the coin's edges move with the light) and a
(8, 5) px move from image 31 is measured on those images as (7.2–8.0, 3.5–4.9) px. A peak on
the border of the search is no measurement, so a move of more than about 11 px is not
measured here: it is left to the QA's drift against the fit (which, against a fit that
explains the images poorly, claims a move only where these edges show it: there, such a move
is not claimed). A shift of more than a pixel counts only if the edge image moved back by it
agrees with the reference better than as it is. The sub-pixel offset is OpenCV's (the 5 x 5
centroid of the signed correlation about the peak); when that centroid lies more than a pixel
from the peak, the peak's negative side-lobes placed it (a weak peak: a second reader's 1000
noisy trials had 453 of 775 correct peaks end more than a pixel off), and it is no
measurement. (The 3 x 3 centroid of the peak's positive part is more precise on shifted copies
of these edge images, 0.12 px mean error against 0.14, and was tried: it narrowed the coin's
spread until its edges were "trusted", and a still 12-light coin session then had an image
called moved by 2 px. Not kept.)

The reference holds the image it is correlated with, and that limits a lone moved image. In a
median of 12 the measured image sets half of every pixel where its value is one of the middle
two, so its own noise sits in the reference at zero shift, and the whitened correlation has a
spike there whatever the image's position. The shipped dome's coin (1024 px, 12 lights, seeds
0-3), image_011 rolled (2, 1) px: at (0, 0) the surface reads 0.09-0.11 against the median of
all, -0.02-0.02 against the median of the others; at (2, 1) 0.04-0.11. On seeds 1-3 the spike is
the peak (no sub-pixel estimate then names the move); on seed 0 the peak is at (2, 1) with the
spike inside its 5 x 5 centroid, which it pulls more than a pixel off (no measurement in round
1; OpenCV 5.0's third round measured (1.9, 1.6), 5.1's did not). Tried and not kept
(benchmarks/qa_glossy_move_margin.py's sessions, QA through the CLI, OpenCV 5.0 and 5.1): the
parabolic peak on the 3 samples each axis names the move on seeds 0 and 2 (5.1: 0, 2, 3) but
narrows the still spread to 0.13-0.28 px, so a still seed-2 session had image_005 called moved
by 2.2 px (5.0); the others' median (leave-one-out) with the same centroid places few still
images (2-6 of 12: edges not trusted); the others' median with the surface blurred (sigma 2 px)
and a parabolic peak places image_011 at 1.9-2.5 px on all 8 moved sessions, the still images'
largest at 1.2-1.7 px, but reads the coin's spread as 0.44-0.92 px (not trusted), names the
move on one seed of four on each OpenCV and drops the still sessions' "not judged" note. The
coin's edges look trusted partly by this spike; a measure without it must be judged on every
QA test's scene.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from rti_rig.reconstruct.qa_bands import median_of_images

#: Blur (sigma, pixels) before the gradient: noise out, edges kept.
EDGE_BLUR = 1.5
#: A phase-correlation peak below this response is no measurement (no common structure).
MIN_RESPONSE = 0.03
#: Rounds of (median reference, shifts, move back).
ROUNDS = 3
#: Bytes of edge-image spectra :class:`EdgeImages` keeps for reuse (about 1.2 MB a spectrum of
#: a 384 px crop: 48 images take 57 MB); past it a spectrum is computed afresh each time, the
#: same bits, so a dense acquisition's QA does not grow by a spectrum per light.
SPECTRA_KEPT_BYTES = 128 * 2**20
#: The phase-correlation peak is searched within this many pixels of no shift (each axis); a
#: peak on the border is rejected, so the largest shift measured is about one pixel less.
MAX_SHIFT_PX = 12
#: A shift up to this (pixels) is taken as found; a larger one must be confirmed.
CONFIRM_ABOVE_PX = 1.0


def edge_image(img: NDArray[np.float32]) -> NDArray[np.float32] | None:
    """Gradient magnitude scaled by its 99th percentile, or None for a featureless image."""
    g = cv2.GaussianBlur(img.astype(np.float32), (0, 0), EDGE_BLUR)
    gx = cv2.Sobel(g, cv2.CV_32F, 1, 0)
    gy = cv2.Sobel(g, cv2.CV_32F, 0, 1)
    m = np.hypot(gx, gy)
    scale = float(np.percentile(m, 99.0))
    if not np.isfinite(scale) or scale <= 0:
        return None
    return np.minimum(m / scale, 2.0)


class EdgeImages:
    """The edge images of one crop stack (:func:`edge_image` of each usable image; None for
    the others) and the median of all of them, made once for :func:`step_candidates` and
    :func:`measure_drift` alike.

    Why: the QA ran both on the same stack when no step was found (every still session), and
    each made the 48 edge images (a blur, two Sobels and a percentile apiece) and their median
    over again: the same values, computed twice. Valid only for the stack it was made of: a
    caller that moves images back makes a new one."""

    def __init__(self, crops: NDArray[np.float32], usable: NDArray[np.bool_]) -> None:
        self.edges = [edge_image(c) if usable[i] else None for i, c in enumerate(crops)]
        self.have = [i for i in range(crops.shape[0]) if self.edges[i] is not None]
        self._median_all: NDArray[np.float32] | None = None
        self._spectra: dict[int, NDArray[np.complex128]] = {}
        self._medians: dict[tuple[int, ...], NDArray[np.float32]] = {}
        #: The Hanning window of the crops' shape both searches correlate under.
        self.window: NDArray[np.float64] = _hanning(crops.shape[1:3])

    def spectrum(self, i: int, window: NDArray[np.float64]) -> NDArray[np.complex128]:
        """:func:`_spectrum` of edge image ``i`` (float64) under ``window``, made once.

        Why: measure_drift's three rounds and step_candidates' peaks each took the windowed
        FFT of every edge image again (four times the same 48 spectra on a still session);
        the edge images do not change. Cached only under :attr:`window` (any other window is
        computed afresh), and up to :data:`SPECTRA_KEPT_BYTES`."""
        edge = self.edges[i]
        assert edge is not None  # only images in ``have`` are correlated
        if window is not self.window:
            return _spectrum(edge.astype(np.float64), window)
        cached = self._spectra.get(i)
        if cached is None:
            cached = _spectrum(edge.astype(np.float64), window)
            if (len(self._spectra) + 1) * cached.nbytes <= SPECTRA_KEPT_BYTES:
                self._spectra[i] = cached
        return cached

    def median_of(self, images: list[int]) -> NDArray[np.float64]:
        """``median_of_images`` of those edge images, float64 (the median of every usable
        one kept, as both callers take it first; any other set's kept as well: the step
        search's refinements and its three seeds judge the same before and after sides
        again, each a median of up to 48 edge images made anew)."""
        if images == self.have:
            if self._median_all is None:
                self._median_all = median_of_images([self.edges[i] for i in images])
            return self._median_all.astype(np.float64)
        key = tuple(images)
        kept = self._medians.get(key)
        if kept is None:
            kept = self._medians[key] = median_of_images([self.edges[i] for i in images])
        return kept.astype(np.float64)


def _hanning(shape: tuple[int, ...]) -> NDArray[np.float64]:
    """The Hanning window both searches use for edge images of ``shape`` (h, w)."""
    return cv2.createHanningWindow((shape[1], shape[0]), cv2.CV_64F)


def _move(img: NDArray, dx: float, dy: float) -> NDArray:
    m = np.float32([[1, 0, dx], [0, 1, dy]])
    return cv2.warpAffine(
        img, m, (img.shape[1], img.shape[0]), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT
    )


def _agreement(ref: NDArray, edge: NDArray, dx: float, dy: float) -> tuple[float, float]:
    """Normalised correlation with ``ref`` of ``edge`` as it is and moved back by
    ``(dx, dy)``, both over the pixels that stay inside the image after the move (NaN when
    none do)."""
    h, w = edge.shape
    px, py = int(np.ceil(abs(dx))) + 1, int(np.ceil(abs(dy))) + 1
    if h <= 2 * py + 4 or w <= 2 * px + 4:
        return float("nan"), float("nan")
    inner = (slice(py, h - py), slice(px, w - px))
    r = ref[inner].ravel()

    def ncc(a: NDArray) -> float:
        a = a[inner].ravel().astype(np.float64)
        a, b = a - a.mean(), r - r.mean()
        d = float(np.sqrt((a @ a) * (b @ b)))
        return float(a @ b) / d if d > 0 else float("nan")

    return ncc(edge), ncc(_move(edge, -dx, -dy))


def _confirmed(ref: NDArray, edge: NDArray, dx: float, dy: float) -> bool:
    """Is the shift the correlation found a measurement (see the module's docstring)?"""
    if np.hypot(dx, dy) <= CONFIRM_ABOVE_PX:
        return True
    as_is, moved_back = _agreement(ref, edge, dx, dy)
    return bool(moved_back > as_is)


def local_phase_correlation(
    ref: NDArray[np.float64], img: NDArray[np.float64], window: NDArray[np.float64]
) -> tuple[tuple[float, float], float]:
    """``(dx, dy)`` of ``img`` against ``ref`` and the peak's response, as OpenCV's
    ``phaseCorrelate`` (windowed, normalised cross-power spectrum; 5 × 5 weighted centroid;
    the response is the correlation summed over it), but with the peak searched only within
    :data:`MAX_SHIFT_PX` of no shift. A peak on the search's border, or one lower than the
    highest outside it, gives NaN: the shift may be larger, or the image matches itself
    elsewhere as well — either way it is no measurement; so does a centroid more than a pixel
    from the peak (module docstring)."""
    return _peak_near_zero(_spectrum(ref, window), img, window)


def _spectrum(img: NDArray[np.float64], window: NDArray[np.float64]) -> NDArray[np.complex128]:
    return np.fft.rfft2(img * window)


def _correlation(
    ref_spectrum: NDArray[np.complex128], img: NDArray[np.float64], window: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The phase correlation surface of ``img`` against the reference, no shift at its centre."""
    return _cross_correlation(ref_spectrum, _spectrum(img, window), img.shape)


def _cross_correlation(
    ref_spectrum: NDArray[np.complex128],
    spectrum: NDArray[np.complex128],
    shape: tuple[int, ...],
) -> NDArray[np.float64]:
    """:func:`_correlation` from the image's spectrum (made once for several references)."""
    cross = np.conj(ref_spectrum) * spectrum
    cross /= np.maximum(np.abs(cross), 1e-30)
    return np.fft.fftshift(np.fft.irfft2(cross, s=shape))


def _peak_near_zero(
    ref_spectrum: NDArray[np.complex128], img: NDArray[np.float64], window: NDArray[np.float64]
) -> tuple[tuple[float, float], float]:
    """:func:`local_phase_correlation` with the reference's spectrum computed once a round."""
    return _peak_of(_correlation(ref_spectrum, img, window))


def whole_pixel_peak(corr: NDArray[np.float64]) -> tuple[tuple[int, int] | None, float]:
    """The correlation peak's ``(y, x)`` within ``MAX_SHIFT_PX`` of zero shift, and its 5 x 5
    sum; ``None`` (with the strength to report) where it lies on the search's border or is
    not the surface's maximum. Shared by :func:`_peak_of` and benchmarks/qa_step_margin.py's
    alternative placement of the same peak, so both judge one peak."""
    h, w = corr.shape
    cy, cx = h // 2, w // 2
    r = min(MAX_SHIFT_PX, cy - 3, cx - 3)
    if r < 2:  # too small an image for a search with a border
        return None, 0.0
    near = corr[cy - r : cy + r + 1, cx - r : cx + r + 1]
    iy, ix = np.unravel_index(int(np.argmax(near)), near.shape)
    if iy in (0, 2 * r) or ix in (0, 2 * r) or corr.max() > near[iy, ix]:
        return None, float(near[iy, ix])
    y, x = cy - r + int(iy), cx - r + int(ix)
    return (y, x), float(corr[y - 2 : y + 3, x - 2 : x + 3].sum())


def _peak_of(corr: NDArray[np.float64]) -> tuple[tuple[float, float], float]:
    """:func:`_peak_near_zero` on a correlation surface already made."""
    peak, total = whole_pixel_peak(corr)
    if peak is None:
        return (float("nan"), float("nan")), total
    y, x = peak
    cy, cx = corr.shape[0] // 2, corr.shape[1] // 2
    patch = corr[y - 2 : y + 3, x - 2 : x + 3]
    if total <= 0:
        return (float("nan"), float("nan")), total
    ys, xs = np.mgrid[-2:3, -2:3]
    ox, oy = float((xs * patch).sum()) / total, float((ys * patch).sum()) / total
    if max(abs(ox), abs(oy)) > 1.0:  # side-lobes, not the peak, placed it: no measurement
        return (float("nan"), float("nan")), total
    return (x - cx + ox, y - cy + oy), total


def measure_drift(
    crops: NDArray[np.float32],
    usable: NDArray[np.bool_],
    edge_set: EdgeImages | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per image ``(dx, dy)`` (image axes, x right, y down) against the session's median edge
    image, and the correlation response. ``usable`` False (a dark or misfired frame), a
    featureless image or a shift not confirmed gives NaN: not measured. ``edge_set``: the
    :class:`EdgeImages` of these ``crops`` and ``usable`` already made (else made here)."""
    n = crops.shape[0]
    if edge_set is None:
        edge_set = EdgeImages(crops, usable)
    edges, have = edge_set.edges, edge_set.have
    shifts = np.zeros((n, 2))
    measured = np.zeros(n, bool)
    response = np.zeros(n)
    if len(have) < 3:
        return np.full((n, 2), np.nan), response
    window = edge_set.window
    for _ in range(ROUNDS):
        # only measured shifts move an image back: a wrong one would drag the reference
        # (an image not moved is itself, not a warped copy: the identity warp gives the same
        # values, and a copy of every edge image had set the QA's peak at many lights)
        if not shifts.any():  # none moved back: the median of the edge images as they are
            ref = edge_set.median_of(have)
        else:
            back = [
                _move(edges[i], -shifts[i, 0], -shifts[i, 1]) if shifts[i].any() else edges[i]
                for i in have
            ]
            ref = median_of_images(back).astype(np.float64)
            del back
        ref_spectrum = _spectrum(ref, window)
        for i in have:
            e = edges[i].astype(np.float64)
            corr = _cross_correlation(ref_spectrum, edge_set.spectrum(i, window), e.shape)
            (dx, dy), r = _peak_of(corr)
            response[i] = r
            measured[i] = bool(np.isfinite(dx)) and r >= MIN_RESPONSE and _confirmed(ref, e, dx, dy)
            shifts[i] = (dx, dy) if measured[i] else (0.0, 0.0)
    out = np.full((n, 2), np.nan)
    out[measured] = shifts[measured]
    return out, response


#: A step (one move part-way through the session) is looked for only with at least this many
#: images whose edges can be placed on each side of it.
STEP_MIN_IMAGES = 3
#: ... and when at least this share of the images on each side sit where the step says.
STEP_AGREE = 0.75
#: ... and is a move when the two sides' median edge images lie further apart than this
#: (pixels): the per-image judgement's :data:`~rti_rig.reconstruct.qa.DRIFT_PX`.
STEP_PX = 1.0


@dataclass(frozen=True)
class Step:
    """The object or the camera moved once, between images ``first - 1`` and ``first``
    (0-based, capture order), by ``shift`` (image axes, x right, y down): the images from
    ``first`` on against the images before it."""

    first: int
    shift: tuple[float, float]
    #: The share of the images whose edges were placed that sit where the step says (those
    #: before it at the first position, those from it on at the second): how well the edges
    #: alone bear this split out, what tells candidates apart where no fit can
    #: (:func:`~rti_rig.reconstruct.qa._confirmed_step`).
    agreement: float = 1.0
    #: Where the move may have begun as early as this image (0-based, before ``first``): the
    #: edges bear out splits from here to ``first`` alike and no fit tells them apart. None:
    #: placed at ``first``.
    earliest: int | None = None
    #: Where the move may have begun as late as this image (0-based, from ``first`` on), set
    #: with ``earliest``: the images from ``earliest`` up to it may or may not have moved.
    latest: int | None = None
    #: The first and the last image the move may have begun at by the images' own labels
    #: (:func:`step_candidates`): an image before ``first`` read as moved, or one from it on
    #: read as still, leaves the split's place open that far. ``first`` twice: every image
    #: sits where the split says.
    span: tuple[int, int] | None = None


def find_step(crops: NDArray[np.float32], usable: NDArray[np.bool_]) -> Step | None:
    """The first of :func:`step_candidates`, or None."""
    return next(step_candidates(crops, usable), None)


#: Two images, one each side of a split, are lit alike when their lights lie within this
#: angle (degrees) of each other: 48 lights on the hemisphere lie about 19 degrees from their
#: nearest (the virtual arm's 48: 18.2-19.1), so an image's nearest neighbours pair, and no
#: light from the other half of the hemisphere does.
LIT_ALIKE_DEG = 30.0


def lit_alike(
    lights: NDArray[np.float64], before: list[int], after: list[int]
) -> list[tuple[int, int]]:
    """Pairs ``(i, j)``, ``i`` from ``before`` and ``j`` from ``after``, each image in one
    pair at most, whose lights lie within :data:`LIT_ALIKE_DEG` of each other (closest pairs
    first, greedily).

    Why: in the arm's move-time order the lights sweep the hemisphere by azimuth, so the
    images before a split are lit from one side and those after it from the other; their
    median edge images then differ by their shading edges as well as by any move. On the
    virtual arm's 256 px industrial part (48 lights, moved (1, 2) px from image 25) the two
    sides' correlation peak was weak (response 0.28) and its centroid lay over a pixel off:
    no step. The images of the two sides lit alike (8 pairs) placed the move at (0.84, 2.16)
    px, response 0.60."""
    if not before or not after:
        return []
    # a light not known (NaN) is lit like none
    cos = np.nan_to_num(lights[before] @ lights[after].T, nan=-1.0)
    limit = float(np.cos(np.radians(LIT_ALIKE_DEG)))
    pairs: list[tuple[int, int]] = []
    used_a: set[int] = set()
    used_b: set[int] = set()
    for k in np.argsort(-cos, axis=None, kind="stable"):
        i, j = np.unravel_index(int(k), cos.shape)
        if cos[i, j] < limit:
            break
        if int(i) in used_a or int(j) in used_b:
            continue
        used_a.add(int(i))
        used_b.add(int(j))
        pairs.append((before[int(i)], after[int(j)]))
    return pairs


def step_candidates(
    crops: NDArray[np.float32],
    usable: NDArray[np.bool_],
    edge_set: EdgeImages | None = None,
    lights: NDArray[np.float64] | None = None,
) -> Iterator[Step]:
    """Moves part-way through the session (a step in the per-image shifts) the edges bear
    out, most likely first, each with a different first image (none: none found).

    Why: when the object moves for a good part of a session (from image 25 of 48, or 7 of 12)
    every reference the per-image checks use is a blend of the two positions. The median edge
    image of :func:`measure_drift` is half one and half the other, each image's peak against it
    is a double one whose centroid is refused (or lands half-way), and the fit blends the two
    as well: a move of (1, 2) px from image 25 of 48 was named on 10 of its 24 images, one of
    (2, 0) px from image 7 of 12 on none ("good"). Two positions are plain in the *integer*
    peaks against that median, though (0 before the move, the move after it, on the emulated
    dome's 48 images), and the capture order says they form two runs.

    So: the whole-pixel peak of each image's edges against the session's median edge image;
    the split of the capture order into a before and an after that separates those peaks best
    (the largest between-group sum of squares, each side at least :data:`STEP_MIN_IMAGES`
    placed images); then the two sides' own median edge images, each made at one position and
    over many lights (a light's own shading edges average out), correlated against each other
    (sub-pixel, :func:`local_phase_correlation`). It is a move when they lie more than
    :data:`STEP_PX` apart, the after side moved back by it agrees with the before side better
    than as it is (:func:`_confirmed` logic), and the split's peaks agree with that shift.

    The first split comes from the peaks against the median of every image; then from the
    peaks against the median of the first half of the images, then of the second half. When
    the move falls half-way, the median of all holds both positions equally and every peak
    against it sits at 0 (no split: the painting moved (1, 2) px from image 7 of 12 was named
    on two scattered images, neither of them moved); a half that lies on one side of the move
    holds that position alone, and the other side's peaks stand off it by the move. A caller
    that confirms a candidate another way (:func:`~rti_rig.reconstruct.qa._confirmed_step`)
    takes the next when one is refused.

    ``edge_set``: the :class:`EdgeImages` of these ``crops`` and ``usable`` already made (else
    made here). ``lights`` (unit vectors, one per image): the two sides are then the medians
    of their images lit alike (:func:`lit_alike`) where at least :data:`STEP_MIN_IMAGES`
    pairs are, for the shift and each image's label alike; a capture order that sweeps the
    hemisphere (the arm's) lights the two sides from different halves, and their shading
    edges differ as well.
    """
    n = crops.shape[0]
    if edge_set is None:
        edge_set = EdgeImages(crops, usable)
    edges, have = edge_set.edges, edge_set.have
    if len(have) < 2 * STEP_MIN_IMAGES:
        return
    window = edge_set.window
    median_of = edge_set.median_of

    def peaks_against(refs: list[NDArray[np.float64]]) -> list[NDArray[np.float64]]:
        """Each image's whole-pixel peak against each of ``refs`` (NaN: none within the
        search). All references at once: each image's spectrum is made once for all of them
        (one a reference, it had been made three times over for the three seeds below)."""
        outs = [np.full((n, 2), np.nan) for _ in refs]
        h, w = refs[0].shape
        cy, cx = h // 2, w // 2
        r = min(MAX_SHIFT_PX, cy - 3, cx - 3)
        if r < 2:
            return outs
        ref_spectra = [_spectrum(ref, window) for ref in refs]
        for i in have:
            spectrum = edge_set.spectrum(i, window)
            for out, ref_spectrum in zip(outs, ref_spectra, strict=True):
                corr = _cross_correlation(ref_spectrum, spectrum, edges[i].shape)
                near = corr[cy - r : cy + r + 1, cx - r : cx + r + 1]
                iy, ix = np.unravel_index(int(np.argmax(near)), near.shape)
                if near[iy, ix] >= MIN_RESPONSE and 0 < iy < 2 * r and 0 < ix < 2 * r:
                    out[i] = (ix - r, iy - r)
        return outs

    def best_split(peaks: NDArray[np.float64]) -> int | None:
        """The first image after the split of the capture order that separates the placed
        peaks best (largest between-group sum of squares)."""
        placed = np.flatnonzero(np.isfinite(peaks[:, 0]))
        p, m = peaks[placed], placed.size
        best, split = 0.0, -1
        for k in range(STEP_MIN_IMAGES, m - STEP_MIN_IMAGES + 1):
            gap = p[:k].mean(axis=0) - p[k:].mean(axis=0)
            score = float(gap @ gap) * k * (m - k) / m
            if score > best:
                best, split = score, k
        return int(placed[split]) if split >= 0 else None

    def moved_labels(ref: NDArray[np.float64], dx: float, dy: float) -> NDArray[np.float64]:
        """1 where an image's edges moved back by ``(dx, dy)`` agree with ``ref`` better than
        as they are, 0 where worse, NaN where not measured."""
        out = np.full(n, np.nan)
        for i in have:
            as_is, back = _agreement(ref, edges[i], dx, dy)
            if np.isfinite(as_is) and np.isfinite(back):
                out[i] = float(back > as_is)
        return out

    def label_split(labels: NDArray[np.float64]) -> int | None:
        """The first image after the split that the labels agree with most."""
        known = np.flatnonzero(np.isfinite(labels))
        lab, m = labels[known], known.size
        best, split = -1.0, -1
        for k in range(STEP_MIN_IMAGES, m - STEP_MIN_IMAGES + 1):
            agree = float((lab[:k] == 0).sum() + (lab[k:] == 1).sum())
            if agree > best:
                best, split = agree, k
        return int(known[split]) if split >= 0 else None

    def sides(first: int | None) -> tuple[list[int], list[int]] | None:
        if first is None:
            return None
        before = [i for i in have if i < first]
        after = [i for i in have if i >= first]
        if len(before) < STEP_MIN_IMAGES or len(after) < STEP_MIN_IMAGES:
            return None
        return before, after

    def side_medians(before: list[int], after: list[int]) -> tuple[NDArray, NDArray]:
        """The two sides' median edge images: of their images lit alike (:func:`lit_alike`)
        where ``lights`` are given and at least :data:`STEP_MIN_IMAGES` pairs are, else of
        every image of each side. The shift is measured between them, each image is
        labelled against the first, and the two must agree better moved back."""
        pairs = lit_alike(lights, before, after) if lights is not None else []
        if len(pairs) >= STEP_MIN_IMAGES:
            return median_of([i for i, _ in pairs]), median_of([j for _, j in pairs])
        return median_of(before), median_of(after)

    def judged(first: int | None) -> Step | None:
        """The step the split before ``first`` refines to, if the images bear it out."""
        # The shift between the two sides' medians, and each image labelled by whether its
        # edges moved back by that shift agree better with the before side's (a hypothesis
        # test, no peak to find: an image under a grazing or weak light places no peak, but
        # still tells which of two known positions it is at); the split the labels agree
        # with most, up to three times.
        for rnd in range(4):  # three refinements; the split they end on is judged below
            split = sides(first)
            if split is None:
                return None
            before, after = split
            ref_a, ref_b = side_medians(before, after)
            (dx, dy), response = local_phase_correlation(ref_a, ref_b, window)
            if not np.isfinite(dx) or response < MIN_RESPONSE or np.hypot(dx, dy) <= STEP_PX:
                return None
            labels = moved_labels(ref_a, dx, dy)
            refined = label_split(labels) if rnd < 3 else first
            if refined == first:
                break
            first = refined
        as_is, moved_back = _agreement(ref_a, ref_b, dx, dy)
        if not moved_back > as_is:
            return None
        # the images, one by one, must sit where the step says: most of those after it at
        # the move, most of those before at none (two groups of lights whose shading edges
        # differ would not)
        la, lb = labels[before], labels[after]
        la, lb = la[np.isfinite(la)], lb[np.isfinite(lb)]
        if la.size < STEP_MIN_IMAGES or lb.size < STEP_MIN_IMAGES:
            return None
        if la.mean() > 1 - STEP_AGREE or lb.mean() < STEP_AGREE:
            return None
        assert first is not None  # sides() refused None
        agreement = float(((la == 0).sum() + (lb == 1).sum()) / (la.size + lb.size))
        early = [i for i in before if labels[i] == 1]
        late = [i + 1 for i in after if labels[i] == 0]
        span = (min(early, default=first), min(max(late, default=first), n - 1))
        return Step(first, (float(dx), float(dy)), agreement, span=span)

    # The first split, from the whole-pixel peaks against the median of every image; failing
    # that, against the median of the first half of the images, then of the second half
    # (the seeds): a move between a quarter and three quarters of the way through
    # leaves one half at one position, whose median holds that position's edges alone.
    half = len(have) // 2
    seen: set[int] = set()
    seeds = [seed for seed in (have, have[:half], have[half:]) if len(seed) >= STEP_MIN_IMAGES]
    # every seed's peaks are taken (the QA judges every candidate): in one pass over the images
    peaks = peaks_against([median_of(seed) for seed in seeds])
    for seed_peaks in peaks:
        step = judged(best_split(seed_peaks))
        if step is not None and step.first not in seen:
            seen.add(step.first)
            yield step


#: The edge shifts are trusted when their robust spread about the session's median is at
#: most this (pixels).
TRUSTED_SPREAD_PX = 0.35


def edge_shifts_trusted(shifts: NDArray[np.float64]) -> tuple[bool, NDArray[np.float64]]:
    """Are the edge shifts a measurement on this object (robust spread about their median at
    most :data:`TRUSTED_SPREAD_PX`)? Returns that and each image's shift from the median
    (NaN where not measured). A block of moved images is a minority or the majority: either
    way the median sits on one block and the spread on that block's noise."""
    ok = np.isfinite(shifts[:, 0])
    dev = np.full_like(shifts, np.nan)
    if ok.sum() < 5:
        return False, dev
    centre = np.median(shifts[ok], axis=0)
    for _ in range(3):  # the centre of the largest block, not between two blocks
        near = ok & (np.hypot(*(shifts - centre).T) <= 1.0)
        if near.sum() < max(3, ok.sum() // 2):
            break
        centre = np.median(shifts[near], axis=0)
    dev[ok] = shifts[ok] - centre
    spread = still_spread_px(dev)
    return bool(spread <= TRUSTED_SPREAD_PX), dev


#: The edge noise is measured only on at least this many images that held still.
STILL_MIN_IMAGES = 6


def still_spread_px(dev: NDArray[np.float64]) -> float:
    """The robust spread (pixels) of the edge shifts of the images that held still (within a
    pixel of the session's centre; ``dev`` from :func:`edge_shifts_trusted`): the noise of this
    object's edge shifts. Infinite when fewer than half the measured images held still, or
    fewer than :data:`STILL_MIN_IMAGES`.

    Why the floor: the centre is the median of these same shifts, so with an odd count one
    image sits on it and reads 0 px, and of three still images the median distance is the
    smaller of the other two. The emulated Nab dome's 48 px glossy coin under uneven LEDs
    (``led_power_spread = 0.2``, seed 1), still, had 5 of 12 images' edges placed, 3 of them
    within a pixel of the centre (0, 0.18 and 0.36 px off): a spread of 0.27 px, its edges
    "trusted", and the two others, 1.33 px off where the highlights moved with the light, were
    called moved. Six still images leave the 12-light tablet's (11-12 placed) judged as before."""
    ok = np.isfinite(dev[:, 0])
    dist = np.hypot(dev[ok, 0], dev[ok, 1])
    still = dist[dist <= 1.0]
    # the still images are measured ones, so this floor covers the five measured it also had
    if still.size < max(STILL_MIN_IMAGES, (ok.sum() + 1) // 2):
        return float("inf")
    return 1.4826 * float(np.median(still))


def light_trend(dev: NDArray[np.float64], lights: NDArray) -> NDArray[np.float64]:
    """The part of each image's edge shift (``dev`` from :func:`edge_shifts_trusted`, image
    axes) that is linear in its light's horizontal direction (``lights`` (N, 3)), fitted on
    the images that held still (within a pixel of the centre); zeros when fewer than 6 did
    (3 coefficients an axis need some slack) or where a shift is NaN.

    Why: shading edges lean towards the light. The emulated dome's 48 px tablet, still, with
    uneven LEDs (``led_power_spread = 0.2``) had its edges trusted (median spread 0.25 px; 0.37
    with even LEDs, not trusted) while their x shift followed the light's x (correlation
    0.94), and the image of its most grazing light, 1.2 px off along that light, was called
    moved on its edges' word alone. A moved image does not follow its light: its shift stays
    outside the trend, which is fitted without it."""
    lt = np.asarray(lights, dtype=np.float64)
    out = np.zeros_like(dev)
    fin = np.isfinite(dev[:, 0])
    still = fin & (np.hypot(*np.nan_to_num(dev).T) <= 1.0)
    if still.sum() < 6:
        return out
    design = np.column_stack([np.ones(int(still.sum())), lt[still, 0], lt[still, 1]])
    coef, *_ = np.linalg.lstsq(design, dev[still], rcond=None)
    out[fin] = lt[fin, :2] @ coef[1:]
    out[fin] -= np.median(out[still], axis=0)  # the still images' centre stays where it is
    return out


#: An image's edges claim a move on their own only where the session's still images' edges
#: agree with their median edge image (normalised correlation) by at least this much: below
#: it the edges carry no position. The emulated Nab dome's featureless flat plate (24 lights)
#: reads 0.12-0.33 (a 2 px move of one image read (0.7, 1.8) px: its edges are the noise and
#: the lamps' fall-off), the tilted relief 0.36-0.88 (median 0.75), the industrial part
#: about 0.45-0.7.
EDGE_STRUCTURE_MIN = 0.4
#: ... and only where the image's own edges, moved back by the shift, agree with that median
#: by at least this share of the still images' median agreement: a shadow's edge under a
#: grazing light is no image of the object's edges. The emulated minirti dome's tilted relief
#: (24 lights, uneven LEDs, seed 3), still: its image_006, 96 % in shadow, read 8.5 px off
#: at 0.32 against the still images' 0.75 and was called moved; the same relief's image_010
#: moved 2 px reads 0.77 moved back (0.33 as it is).
EDGE_AGREE_SHARE = 0.5


def edge_agreement(crops: NDArray[np.float32], shifts: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each measured image's edge image, moved back by its shift (``shifts`` from
    :func:`measure_drift`, NaN where not measured), correlated with the median of all the
    measured images' edges moved back likewise (NaN where not measured).

    Why: the shift of one image's edges is a position only where the edges are the object's.
    A featureless plate's edges are noise and the lamps' fall-off, and an image almost all in
    shadow shows only its shadow's edge, which moves with the light: both read shifts of
    several pixels in still sessions, and were called moved on that alone."""
    n = crops.shape[0]
    out = np.full(n, np.nan)
    ok = np.isfinite(shifts[:, 0])
    edges = {int(i): edge_image(crops[i]) for i in np.flatnonzero(ok)}
    have = [i for i, e in edges.items() if e is not None]
    if len(have) < 3:
        return out
    back = [_move(edges[i], -shifts[i, 0], -shifts[i, 1]) for i in have]
    ref = np.median(np.stack(back), axis=0).astype(np.float64)
    for i in have:
        out[i] = _agreement(ref, edges[i], float(shifts[i, 0]), float(shifts[i, 1]))[1]
    return out


def edges_place(agreement: NDArray[np.float64], still: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Which images' edges can place them on their own (``agreement`` from
    :func:`edge_agreement`; ``still`` the images that held still): none where the still
    images' median agreement is below :data:`EDGE_STRUCTURE_MIN`, else those at least
    :data:`EDGE_AGREE_SHARE` of it."""
    base = agreement[still & np.isfinite(agreement)]
    if base.size == 0:
        return np.zeros(agreement.shape, bool)
    typical = float(np.median(base))
    if typical < EDGE_STRUCTURE_MIN:
        return np.zeros(agreement.shape, bool)
    with np.errstate(invalid="ignore"):
        return np.asarray(agreement >= EDGE_AGREE_SHARE * typical, dtype=bool)


def move_back(img: NDArray, dx: float, dy: float) -> NDArray:
    """The image moved back by its measured shift (edges reflected)."""
    return _move(img, -dx, -dy)


#: A change point needs at least this many measured images on each side: fewer, and the
#: per-image check against a fit made mostly of the other side names them itself.
CHANGE_MIN_BLOCK = 3
#: A change point is a candidate when its two blocks' median shifts differ by this many
#: standard errors (robust, from the blocks' own spread) ...
CHANGE_Z = 4.0
#: ... and by at least this much (pixels). The fit blends the two positions, so each block
#: reads only part of the move against it. Candidates are confirmed by a refit
#: (:func:`~rti_rig.reconstruct.qa._moved_block`).
CHANGE_MIN_PX = 0.5


def change_point(
    shifts: NDArray[np.float64], judged: NDArray[np.bool_]
) -> tuple[int, NDArray[np.float64], float] | None:
    """Where per-image shifts (N, 2) of a session, in capture order, split into an earlier and
    a later block whose median shifts differ by more than their noise: the first image of the
    later block, the later block's median shift minus the earlier's, and that difference in
    robust standard errors. None when no split passes :data:`CHANGE_Z` and
    :data:`CHANGE_MIN_PX` (``judged`` False, or a NaN shift: not used; each block needs
    :data:`CHANGE_MIN_BLOCK` used images).

    Why: where the edges move with the light (the virtual arm's 256 px tablet) the edge-based
    :func:`step_candidates` cannot tell a move from a change of lights, but the shifts of the
    images against a fit can: a fit that blends two positions leaves every image a pixel or
    so off the blend, no single image beyond the per-image threshold, and the images split
    plainly into two clusters in capture order. The noise is each block's spread about its
    own median (1.4826 × MAD, pooled), so a session whose grazing images wander by ±0.7 px
    is not split by them."""
    ok = judged & np.all(np.isfinite(shifts), axis=1)
    idx = np.flatnonzero(ok)
    m = idx.size
    if m < 2 * CHANGE_MIN_BLOCK:
        return None
    s = shifts[idx]
    # the split that best explains the shifts as two still positions (least summed distance
    # to each block's median: one image that wanders does not pull the split to it)
    cost = [
        float(np.hypot(*(s[:c] - np.median(s[:c], axis=0)).T).sum())
        + float(np.hypot(*(s[c:] - np.median(s[c:], axis=0)).T).sum())
        for c in range(CHANGE_MIN_BLOCK, m - CHANGE_MIN_BLOCK + 1)
    ]
    cut = CHANGE_MIN_BLOCK + int(np.argmin(cost))
    a, b = s[:cut], s[cut:]
    ma, mb = np.median(a, axis=0), np.median(b, axis=0)
    diff = mb - ma
    dev = np.concatenate([np.hypot(*(a - ma).T), np.hypot(*(b - mb).T)])
    # 2-D distances of normal noise (Rayleigh): their median is 1.1774 sigma per axis; the
    # floor keeps blocks of near-identical shifts from an infinite z
    sigma = max(float(np.median(dev)) / 1.1774, 0.02)
    se = 1.2533 * sigma * np.sqrt(1.0 / cut + 1.0 / (m - cut))  # of a median
    size = float(np.hypot(*diff))
    if size < CHANGE_MIN_PX or size < CHANGE_Z * se:
        return None
    return int(idx[cut]), diff, size / se


#: Where one group of images' median edges sit between a step's two positions is searched on
#: this grid (fractions of its shift: 0 where the session began, 1 moved by the step), past
#: either end for a group that leans further than the step (:func:`step_follows_elevation`).
_POSITION_GRID = np.linspace(-0.5, 1.5, 21)
#: A step is as well explained by the lights' elevation when, within its side of the higher
#: lights, the higher half's median edges stand at least this share of the step off the lower
#: half's (:func:`step_follows_elevation`).
ELEVATION_STEP_SHARE = 0.5


def step_follows_elevation(
    crops: NDArray[np.float32], usable: NDArray[np.bool_], step: Step, lights: NDArray
) -> bool:
    """Whether ``step`` (found by the edges alone) is as well explained by the lights'
    elevation as by a move: within the side of the step whose lights stand higher, the median
    edges of its higher-lit half sit at least :data:`ELEVATION_STEP_SHARE` of the step's shift
    off those of its lower-lit half (``lights`` (N, 3), z up).

    Why: a real move leaves each side's images at one position, whatever their light; edges
    that change with the light's elevation move within a side as well. On a fibonacci dome
    the capture order is the order of rising elevation (z 0.29 to 0.97 over the shipped 12
    lights), so a split in capture order is a split of low lights from high ones. The emulated
    Nab dome's brushed-steel part, still, uneven LEDs (``led_power_spread = 0.2``), seed 2:
    a (5.0, -1.0) px edges' step (image axes) from image_006, and within the higher side the
    higher half stood 1.1 steps off the lower half; seed 8's (-1.0, -0.9) px step, -0.5. Both were
    "moved part-way through": reshoot the whole session. The glossy coin at 256 px really
    moved 2 px from image 6, 7 or 8 reads 0.1-0.2 there. The lower side is not judged: under
    grazing lights the coin's edges wander by more than the step with the object still
    (1.3-1.5 steps within the lower side of two of those same real moves)."""
    lz = np.asarray(lights, dtype=np.float64)[:, 2]
    n = crops.shape[0]
    sides = list(range(step.first)), list(range(step.first, n))
    high = max(sides, key=lambda s: float(np.mean(lz[s])) if s else -np.inf)
    edges = [(i, edge_image(crops[i])) for i in high if usable[i]]
    edges = [(i, e) for i, e in edges if e is not None]
    if len(edges) < 4:  # two a half at least
        return False  # too few to tell: the step is judged as before
    edges.sort(key=lambda ie: lz[ie[0]])
    half = len(edges) // 2
    low = np.median(np.stack([e for _, e in edges[:half]]), axis=0).astype(np.float64)
    top = np.median(np.stack([e for _, e in edges[half:]]), axis=0).astype(np.float32)
    dx, dy = step.shift
    scores = [_agreement(low, _move(top, -t * dx, -t * dy), 0.0, 0.0)[0] for t in _POSITION_GRID]
    if not np.all(np.isfinite(scores)):
        return False
    position = round(float(_POSITION_GRID[int(np.argmax(scores))]), 6)
    return abs(position) >= ELEVATION_STEP_SHARE
