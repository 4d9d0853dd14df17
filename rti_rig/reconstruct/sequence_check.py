"""Did the camera-triggered dome light the LED its order says? Judged from the images, online.

A dome that steps to its next LED on the camera's flash signal (cceh/rti) cannot be asked what
it lit: the host only shoots, and image *i* is labelled with LED *i* of the firmware's order.
A lost flash pulse (the dome does not step: the image is dark, and every later image is one LED
behind) or a bounced one (the dome steps twice: every later image one LED ahead) would label
every image after it with the wrong light. This module decides, after each capture, whether the
image matches the LED expected, before the label is committed.

Evidence, cheapest first, on the grey image reduced to at most :data:`SIDE` pixels a side:

1. **dark**: the image's 99th percentile below :data:`DARK_RATIO` of the brightest image
   accepted so far (below :data:`DARK_FIRST` of full scale for the first image): no LED lit
   the exposure — the pulse never reached the dome, or the LED it fired is dead. Grazing light
   on a flat, dark or metallic object can be 10 × dimmer than the brightest image; a missed
   pulse or a dead LED leaves only the ambient light inside the dome, far below that. Which of
   the two it was, only the next frame says (:meth:`SequenceChecker.judge_after_dark`): after
   a missed pulse it is lit by the LED the dark image was due, after a dead LED by the next;
2. **which neighbour in the order explains it** (from :data:`MIN_FIT_IMAGES` accepted images
   on): the qa.py machinery — robust Lambertian photometric stereo
   (:func:`~rti_rig.reconstruct.photometric_stereo.fit_photometric_stereo`) on the images
   accepted so far, then the prediction ``rho max(0, n . l)`` of this image under the expected
   LED and under the LEDs before and after it in the order, each with a free gain. A neighbour
   whose relative residual is below :data:`SLIP_RATIO` of the expected LED's is a slip: the
   next LED means a double step, the previous one a missed step. The previous LED lit the last
   image of the fit, which the model reproduces better than any light it extrapolates to, so
   it is judged by the fit without that image, and the image must be that image again
   (:meth:`SequenceChecker._previous_judged_fairly`).

3. **a slip before the neighbour test could run** (images :data:`SHIFT_FROM` + 1 to
   :data:`SHIFT_UNTIL` + 1): a double step in the first images shifts every later image by
   one LED, and the shifted images then explain one another. So the whole set is fitted
   (least-squares photometric stereo) as labelled and under "one LED later (or earlier) from
   image *j* on" for each *j* up to the first neighbour test; a hypothesis whose relative RMS
   residual is :data:`SHIFT_MARGIN` below the labels' is a slip that started at image *j*
   (:attr:`SequenceVerdict.since`). The images from *j* on were labelled before this could
   be known;
4. **where a slip began**: when test 2 finds one at image *i*, the same whole-set comparison
   over "shifted from image *j* on", *j* from *i* − :data:`LOOKBACK` to *i*, says whether
   earlier images were already lit by the wrong LED (a slip test 2 saw only once the
   difference grew, e.g. under grazing light).

Before a fit exists (the first :data:`MIN_FIT_IMAGES` images, or while the lights seen so far
cannot determine a normal) only a dark image is caught. The checker is pure: it holds the
reduced images it accepted and reads no file, no clock, no device.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.rig_geometry import led_said
from rti_rig.reconstruct.errors import ReconstructionError
from rti_rig.reconstruct.photometric_stereo import fit_photometric_stereo
from rti_rig.reconstruct.stack import channel_mean

#: Side (pixels) the images are reduced to for the check (area averaging).
SIDE = 64
#: Images accepted before the neighbour test runs (a fit needs well-spread lights).
MIN_FIT_IMAGES = 3
#: An image whose 99th percentile is below this fraction of the brightest accepted one is dark.
DARK_RATIO = 0.03
#: The first image is dark below this fraction of full scale.
DARK_FIRST = 0.005
#: A neighbour explaining the image with a residual below this fraction of the expected LED's
#: residual is a slip.
SLIP_RATIO = 0.5
#: ...and only if the expected LED's relative residual is above this (noise level: below it the
#: expected LED already explains the image as well as noise allows).
MIN_RESIDUAL = 0.02

#: The blind-spot test (3.) runs on images with these 0-based indices.
SHIFT_FROM, SHIFT_UNTIL = 8, 20
#: ...and names a shift whose residual is this fraction below the labels' residual.
SHIFT_MARGIN = 0.05
#: A slip the neighbour test finds may have begun up to this many images before (test 4).
LOOKBACK = 8

OK, MISSED, DOUBLE = "ok", "missed-step", "double-step"
#: Lit by the first LED of the order far into the run: the dome's firmware started again (its
#: power cycled: cceh/rti's ``led_index`` is zeroed and LED 0 programmed at every start).
RESTARTED = "restarted"


@dataclass(frozen=True)
class SequenceVerdict:
    """The check of image ``index`` (0-based), expected lit by position ``index`` of the order.

    ``kind`` is ``ok``, ``missed-step`` (lit by the previous LED: the dome is behind; or dark,
    with ``dark`` set: a missed pulse or a dead LED, which only the next frame tells apart)
    or ``double-step`` (lit by the next LED: the dome is ahead) or ``restarted`` (lit by the
    order's first LED: the firmware started again from it). ``residuals`` are the relative
    residuals per order position tried; ``fitted`` says whether the neighbour test ran.
    """

    index: int
    kind: str
    reason: str
    best_position: int | None
    fitted: bool
    residuals: dict[int, float] = field(default_factory=dict)
    brightness_ratio: float = float("nan")
    #: For a slip found by the blind-spot test: the image (0-based) it started at.
    since: int | None = None
    #: No LED lit the image. A missed pulse and a dead LED both give one; only the next frame
    #: tells them apart (:meth:`SequenceChecker.judge_after_dark`).
    dark: bool = False

    @property
    def slip(self) -> bool:
        return self.kind != OK

    def to_json(self) -> dict[str, object]:
        return {
            "index": self.index,
            "kind": self.kind,
            "reason": self.reason,
            "best_position": self.best_position,
            "fitted": self.fitted,
            "residuals": {str(k): v for k, v in self.residuals.items()},
            "brightness_ratio": self.brightness_ratio,
            "since": self.since,
            "dark": self.dark,
        }


def reduce_image(pixels: ArrayLike, white_level: float) -> NDArray[np.float32]:
    """Grey, scaled to [0, 1] of the white level, area-reduced to at most :data:`SIDE` a side."""
    a = np.asarray(pixels, dtype=np.float32) / np.float32(max(white_level, 1.0))
    g = channel_mean(a) if a.ndim == 3 else a
    h, w = g.shape
    f = max(1.0, max(h, w) / SIDE)
    size = (max(1, round(w / f)), max(1, round(h / f)))
    return cv2.resize(g, size, interpolation=cv2.INTER_AREA) if f > 1 else g.copy()


def pixel_residual(
    img: NDArray[np.float32], ref: NDArray[np.float32], use: NDArray[np.bool_] | None = None
) -> float:
    """Relative residual of ``img`` against ``ref`` up to a gain, over unsaturated pixels
    (``use``: those of both, by default): how far ``img`` is from being ``ref`` shot again."""
    if use is None:
        use = (img < 1.0) & (ref < 1.0)
    if use.sum() < 10:
        return float("inf")  # too few pixels to say: never "the same image"
    y = img[use].astype(np.float64)
    x = ref[use].astype(np.float64)
    gain = float(x @ y) / max(float(x @ x), 1e-12)
    return float(np.linalg.norm(y - gain * x) / max(np.linalg.norm(y), 1e-12))


class SequenceChecker:
    """Checks each next image against the firmware's order (``order``: (N, 3) directions)."""

    def __init__(self, order: ArrayLike, min_fit_images: int = MIN_FIT_IMAGES) -> None:
        self.order = np.asarray(order, dtype=np.float64).reshape(-1, 3)
        self.min_fit_images = max(3, int(min_fit_images))
        self._images: list[NDArray[np.float32]] = []
        self._lights: list[NDArray[np.float64]] = []
        self._peaks: list[float] = []

    @property
    def accepted(self) -> int:
        return len(self._images)

    @property
    def accepted_images(self) -> list[NDArray[np.float32]]:
        """The reduced images accepted so far, in order (for the end-of-run proof)."""
        return list(self._images)

    def check(self, index: int, pixels: ArrayLike, white_level: float) -> SequenceVerdict:
        """Judge image ``index``; an image judged ``ok`` joins the fit for the next ones."""
        img = reduce_image(pixels, white_level)
        peak = float(np.percentile(img, 99.0))
        ref = max(self._peaks) if self._peaks else 1.0
        ratio = peak / ref if ref > 0 else float("inf")
        if ratio < (DARK_RATIO if self._peaks else DARK_FIRST):
            return SequenceVerdict(
                index,
                MISSED,
                f"dark: its brightest pixels reach {ratio:.0%} of "
                + ("the brightest image's" if self._peaks else "full scale")
                + ": no LED lit the exposure",
                None,
                False,
                brightness_ratio=ratio,
                dark=True,
            )
        verdict = self._neighbour_test(index, img, ratio)
        if verdict.slip and verdict.kind != RESTARTED:
            verdict = self._locate_start(verdict, img)
        else:
            verdict = self._shift_test(index, img, ratio) or verdict
        if not verdict.slip:
            self._images.append(img)
            self._lights.append(self.order[index] if index < len(self.order) else self.order[-1])
            self._peaks.append(peak)
        return verdict

    def judge_after_dark(
        self, index: int, pixels: ArrayLike, white_level: float
    ) -> tuple[float, dict[int, float] | None]:
        """The frame shot after dark image ``index``: its brightness ratio, and its relative
        residuals under order positions ``index`` and ``index + 1`` (None without a fit).

        Why: a missed pulse leaves the dome one LED behind, so that frame is lit by LED
        ``index`` (the one the dark image was due); a dead LED was fired and the dome stepped
        on, so it is lit by LED ``index + 1``, as the order says. The frame joins nothing.
        """
        img = reduce_image(pixels, white_level)
        ref = max(self._peaks) if self._peaks else 1.0
        peak = float(np.percentile(img, 99.0))
        ratio = peak / ref if ref > 0 else float("inf")
        if ratio < (DARK_RATIO if self._peaks else DARK_FIRST):
            return ratio, None
        positions = [p for p in (index, index + 1) if 0 <= p < len(self.order)]
        return ratio, self._residuals(img, positions)

    def _residuals(
        self, img: NDArray[np.float32], positions: list[int], leave_out_last: bool = False
    ) -> dict[int, float] | None:
        """Relative residual of ``img`` under each order position (a free gain each), from the
        robust fit of the accepted images (all but the last with ``leave_out_last``); None
        while no fit can be made."""
        images, lights = self._images, self._lights
        if leave_out_last:
            images, lights = images[:-1], lights[:-1]
        if len(images) < self.min_fit_images:
            return None
        try:
            ps = fit_photometric_stereo(
                np.stack(images), np.stack(lights), robust=True, saturation=1.0
            )
        except ReconstructionError:
            return None  # the lights so far cannot determine a normal
        rho = ps.albedo if ps.albedo.ndim == 2 else ps.albedo.mean(axis=-1)
        use = ps.valid & (img < 1.0)
        if use.sum() < 10:
            return None
        y = img[use].astype(np.float64)
        n = ps.normals[use].astype(np.float64)
        r = rho[use].astype(np.float64)
        residuals: dict[int, float] = {}
        for pos in positions:
            pred = r * np.maximum(n @ self.order[pos], 0.0)
            denom = float(pred @ pred)
            gain = float(pred @ y) / denom if denom > 0 else 0.0
            residuals[pos] = float(np.linalg.norm(y - gain * pred) / max(np.linalg.norm(y), 1e-12))
        return residuals

    def _neighbour_test(
        self, index: int, img: NDArray[np.float32], ratio: float
    ) -> SequenceVerdict:
        none = SequenceVerdict(index, OK, "no fit yet", None, False, brightness_ratio=ratio)
        if len(self._images) < self.min_fit_images or index >= len(self.order):
            return none
        positions = [p for p in (index - 1, index, index + 1) if 0 <= p < len(self.order)]
        # the first LED too: a dome whose power cycled starts its order again there, and every
        # image from then on is labelled with an LED far from the one that lit it (a check of
        # the neighbours alone accepted them all)
        positions += [0] if index >= 2 else []
        residuals = self._residuals(img, positions)
        if residuals is None:
            return none
        expected = residuals[index]
        best = min(residuals, key=lambda p: residuals[p])
        if best == index - 1:
            fair = self._previous_judged_fairly(index, img)
            if (
                fair is not None
                and fair[index - 1] <= SLIP_RATIO * fair[index]
                and pixel_residual(img, self._images[-1]) <= SLIP_RATIO * fair[index]
            ):
                residuals, expected = fair, fair[index]  # its figures, not the biased ones
            else:
                del residuals[index - 1]
                best = min(residuals, key=lambda p: residuals[p])
        if best == 0 and index >= 2 and not self._first_image_again(index, img):
            # the model alone favours a light it was fitted on: on the flat painting a clean
            # image 6 was "explained" by LED 0 at 0.49 of its own LED's residual
            del residuals[0]
            best = min(residuals, key=lambda p: residuals[p])
        if best == index or expected <= MIN_RESIDUAL or residuals[best] > SLIP_RATIO * expected:
            return SequenceVerdict(
                index, OK, "matches its LED", best, True, residuals, brightness_ratio=ratio
            )
        kind = DOUBLE if best == index + 1 else MISSED if best == index - 1 else RESTARTED
        which = {DOUBLE: "next", MISSED: "previous", RESTARTED: "first"}[kind]
        return SequenceVerdict(
            index,
            kind,
            # LEDs named as every other word names them (0-based, with their direction): a
            # 1-based "position 12" beside the CLI's "LED 10 (az …)" named two different LEDs
            f"lit by the {which} LED of the order, {led_said(best, self.order[best])}, not "
            f"{led_said(index, self.order[index])}: relative residual {residuals[best]:.3f} "
            f"against {expected:.3f}",
            best,
            True,
            residuals,
            brightness_ratio=ratio,
        )

    def _previous_judged_fairly(
        self, index: int, img: NDArray[np.float32]
    ) -> dict[int, float] | None:
        """The residuals of ``img`` under the previous LED and the expected one from a fit
        without the last accepted image (the one the previous LED lit); None when that fit
        cannot be made (then no missed step is named here: test 3 may see the shift later,
        and only an order of all the firmware's LEDs has the end-of-run proof behind it).
        The caller also asks the last image itself: a lit missed step on this firmware is the
        LED of the image before lit again, so the image must be that image again (closer to
        it than :data:`SLIP_RATIO` of the expected LED's residual), not merely nearer the
        previous LED's prediction: after an unseen double step at image 1 the mislabelled
        fit put a clean-looking image under the previous LED, and the slip was named a missed
        step beginning at image 3, where the shift test names the double step at image 1.

        Why: the model reproduces the images it was fitted on better than any light it
        extrapolates to, and the previous LED lit the last of them, so the test favoured a
        missed step: on the painting (seed 11) a clean image 6 was put under LED 4 at 0.4996
        of its own LED's residual and a good run was stopped. Over clean runs of the simulated
        scenes that ratio fell to 0.50 with the last image in the fit and stayed above 0.75
        without it, like the next LED's, which no fitted image was lit by either. A lit missed
        step (the firmware re-lighting the LED of the image before, as at its run-out) is then
        told as a double step is: by a light the fit extrapolates to."""
        if len(self._images) != index:
            return None  # the accepted images are not the run's consecutive first ones
        return self._residuals(img, [index - 1, index], leave_out_last=True)

    def _first_image_again(self, index: int, img: NDArray[np.float32]) -> bool:
        """Whether ``img`` is image 1 again (up to a gain), as a dome that started its order
        again lights it: closer to image 1 than :data:`SLIP_RATIO` of its distance to the last
        accepted image, whose LED is the expected one's neighbour.

        Why: the restart is told by the model's prediction under the first LED, and that
        prediction is one of the images the model was fitted on, which it reproduces better
        than any light it extrapolates to. On a flat scene (the painting) every image is nearly
        image 1 up to a gain, and a clean image 6 was called a restart. The same LED lights the
        same pixels: image 1 itself, not the model, is the witness."""
        if len(self._images) != index:
            return False  # the accepted images are not the run's consecutive first ones
        first, last = self._images[0], self._images[-1]
        use = (img < 1.0) & (first < 1.0) & (last < 1.0)
        if use.sum() < 10:
            return False
        return pixel_residual(img, first, use) < SLIP_RATIO * pixel_residual(img, last, use)

    def _whole_set_residual(self, stack: NDArray[np.float32], labels: list[int]) -> float:
        """Relative RMS residual of a least-squares photometric-stereo fit of ``stack``
        labelled with order positions ``labels`` (raises ReconstructionError if it cannot)."""
        lights = self.order[labels]
        ps = fit_photometric_stereo(stack, lights, robust=False, saturation=1.0)
        rho = ps.albedo if ps.albedo.ndim == 2 else ps.albedo.mean(axis=-1)
        pred = np.maximum(np.einsum("hwc,nc->nhw", ps.normals, lights), 0.0) * rho
        use = stack < 1.0
        r = (stack - pred)[use]
        return float(np.sqrt(np.mean(r**2)) / max(np.sqrt(np.mean(stack[use] ** 2)), 1e-12))

    def _locate_start(self, verdict: SequenceVerdict, img: NDArray[np.float32]) -> SequenceVerdict:
        """Test 4: did the slip test 2 found at ``verdict.index`` begin at an earlier image?"""
        index = verdict.index
        step = 1 if verdict.kind == DOUBLE else -1
        n = len(self.order)
        if len(self._images) != index:
            return verdict
        stack = np.stack([*self._images, img])
        found: tuple[float, int] | None = None
        for start in range(max(0, index - LOOKBACK), index + 1):
            labels = [k if k < start else k + step for k in range(index + 1)]
            if min(labels) < 0 or max(labels) >= n:
                continue
            try:
                r = self._whole_set_residual(stack, labels)
            except ReconstructionError:
                continue
            if found is None or r < found[0]:
                found = (r, start)
        if found is None or found[1] == index:
            return verdict
        return SequenceVerdict(
            index,
            verdict.kind,
            f"{verdict.reason}; the images fit best with the slip beginning at image "
            f"{found[1] + 1}",
            verdict.best_position,
            True,
            verdict.residuals,
            verdict.brightness_ratio,
            since=found[1],
        )

    def _shift_test(
        self, index: int, img: NDArray[np.float32], ratio: float
    ) -> SequenceVerdict | None:
        """Test 3: did the labels slip by one LED in the first images (the blind spot)?"""
        n = len(self.order)
        if not SHIFT_FROM <= index <= SHIFT_UNTIL or index >= n:
            return None
        stack = np.stack([*self._images, img])
        positions = [*range(len(self._images)), index]
        if positions[-1] != len(positions) - 1:
            return None  # the accepted images are not the run's consecutive first ones

        def residual(labels: list[int]) -> float:
            return self._whole_set_residual(stack, labels)

        try:
            as_labelled = residual(positions)
        except ReconstructionError:
            return None
        best: tuple[float, int, int] | None = None
        for start in range(0, min(self.min_fit_images, index) + 1):
            for step in (1, -1):
                labels = [p if k < start else p + step for k, p in enumerate(positions)]
                if min(labels) < 0 or max(labels) >= n:
                    continue
                try:
                    r = residual(labels)
                except ReconstructionError:
                    continue
                if r < (1.0 - SHIFT_MARGIN) * as_labelled and (best is None or r < best[0]):
                    best = (r, start, step)
        if best is None:
            return None
        r, start, step = best
        kind, how = (DOUBLE, "stepped twice") if step > 0 else (MISSED, "missed a step")
        return SequenceVerdict(
            index,
            kind,
            f"from image {start + 1} on, the images fit the order one LED "
            f"{'later' if step > 0 else 'earlier'} than labelled (relative residual {r:.3f} "
            f"against {as_labelled:.3f}): the dome {how} at image {start + 1}, before the check "
            "could test it",
            index + step,
            True,
            {index: as_labelled, index + step: r},
            brightness_ratio=ratio,
            since=start,
        )
