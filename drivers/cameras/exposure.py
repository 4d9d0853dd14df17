"""Fix a session's exposure: the longest that keeps saturated pixels under a set fraction.

Why the longest: RTI fits need signal in the shadows, so every extra stop that does not clip is
worth having; clipping, on the other hand, silently breaks the reflectance fit. The rule runs on
*linear* data, so a preview taken at exposure t₀ predicts the frame at t: pixel × t/t₀.
Pixels already saturated in the preview are assumed to stay saturated (their true value is
unknown), which keeps the prediction conservative. Meter at the brightest planned light.

:func:`choose_exposure` and :func:`choose_from_series` are pure; :func:`meter_exposure` drives a
camera through a short test series and verifies the prediction with a real shot.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from rti_rig.core.devices import Camera, Frame
from rti_rig.core.errors import CaptureError
from rti_rig.drivers.cameras.settings import ExposureRule


@dataclass(frozen=True)
class ExposureChoice:
    """The exposure picked for a session and why; ``to_manifest`` is what the manifest records."""

    exposure_s: float
    satisfied: bool
    predicted_saturated_fraction: float
    method: str
    reason: str
    rule: ExposureRule
    measured_saturated_fraction: float | None = None
    test_exposures_s: tuple[float, ...] = field(default_factory=tuple)

    def to_manifest(self) -> dict[str, Any]:
        return {
            "exposure_s": self.exposure_s,
            "satisfied": self.satisfied,
            "method": self.method,
            "reason": self.reason,
            "predicted_saturated_fraction": self.predicted_saturated_fraction,
            "measured_saturated_fraction": self.measured_saturated_fraction,
            "test_exposures_s": list(self.test_exposures_s),
            "rule": self.rule.model_dump(),
        }


def _brightest_channel(frame: Frame) -> np.ndarray:
    return frame.pixels if frame.pixels.ndim == 2 else frame.pixels.max(axis=-1)


def predicted_saturated_fraction(preview: Frame, exposure_s: float, headroom: float = 1.0) -> float:
    """Fraction of pixels saturated at ``exposure_s``, predicted from a linear preview (pure)."""
    if preview.exposure_s <= 0:
        raise ValueError("the preview frame has no exposure time; cannot scale it")
    px = _brightest_channel(preview).astype(np.float64)
    white = float(preview.white_level)
    scale = exposure_s / preview.exposure_s * headroom
    return float(np.mean((px >= white) | (px * scale >= white)))


def _continuous_candidate(preview: Frame, rule: ExposureRule) -> float:
    """Longest exposure in the rule's range meeting the fraction, solved from the pixel order."""
    px = _brightest_channel(preview).ravel()
    white = preview.white_level
    n = px.size
    allowed = int(np.floor(rule.max_saturated_fraction * n))
    unsat = np.sort(px[px < white])[::-1]
    k = allowed - (n - unsat.size)  # unsaturated pixels that may still clip
    if k < 0:
        return rule.min_exposure_s
    if k >= unsat.size or unsat[k] == 0:
        return rule.max_exposure_s
    # the (k+1)-th brightest unsaturated pixel must stay strictly below white
    t = preview.exposure_s * white / (float(unsat[k]) * rule.headroom) * (1 - 1e-6)
    return float(np.clip(t, rule.min_exposure_s, rule.max_exposure_s))


def choose_exposure(
    preview: Frame,
    rule: ExposureRule,
    candidates_s: Sequence[float] | None = None,
) -> ExposureChoice:
    """Pick the longest exposure predicted to keep saturation within ``rule`` (pure).

    ``candidates_s`` are the exposures the camera can actually take (a DSLR's shutter list);
    ``None`` means any value in ``[rule.min_exposure_s, rule.max_exposure_s]``.
    """
    if candidates_s is None:
        options = [_continuous_candidate(preview, rule)]
    else:
        options = sorted(
            {float(c) for c in candidates_s if rule.min_exposure_s <= c <= rule.max_exposure_s}
        )
        if not options:
            raise ValueError(
                f"no candidate exposure lies within [{rule.min_exposure_s}, "
                f"{rule.max_exposure_s}] s"
            )
    predictions = [(t, predicted_saturated_fraction(preview, t, rule.headroom)) for t in options]
    ok = [(t, p) for t, p in predictions if p <= rule.max_saturated_fraction]
    if ok:
        t, p = max(ok)
        reason = (
            f"longest exposure predicted to saturate {p:.4%} of pixels "
            f"(limit {rule.max_saturated_fraction:.4%}) from a {preview.exposure_s:g} s preview"
        )
        return ExposureChoice(
            t, True, p, "preview-prediction", reason, rule, test_exposures_s=(preview.exposure_s,)
        )
    t, p = min(predictions)
    if preview.saturated_fraction > rule.max_saturated_fraction:
        reason = (
            f"the {preview.exposure_s:g} s preview already saturates "
            f"{preview.saturated_fraction:.4%} of pixels: take a shorter preview"
        )
    else:
        reason = (
            f"even {t:g} s is predicted to saturate {p:.4%} of pixels: dim the light, close "
            "the aperture or lower the gain"
        )
    return ExposureChoice(
        t, False, p, "preview-prediction", reason, rule, test_exposures_s=(preview.exposure_s,)
    )


def choose_from_series(series: Sequence[Frame], rule: ExposureRule) -> ExposureChoice:
    """Pick the longest *measured* exposure whose saturated fraction is within the rule (pure)."""
    if not series:
        raise ValueError("choose_from_series needs at least one frame")
    measured = sorted((f.exposure_s, f.saturated_fraction) for f in series)
    tested = tuple(t for t, _ in measured)
    ok = [(t, s) for t, s in measured if s <= rule.max_saturated_fraction]
    if ok:
        t, s = max(ok)
        return ExposureChoice(
            t,
            True,
            s,
            "test-series",
            f"longest test shot within the limit ({s:.4%} saturated)",
            rule,
            s,
            tested,
        )
    t, s = measured[0]
    return ExposureChoice(
        t,
        False,
        s,
        "test-series",
        f"every test shot saturates more than "
        f"{rule.max_saturated_fraction:.4%} (shortest: {s:.4%} at {t:g} s)",
        rule,
        s,
        tested,
    )


def meter_exposure(
    camera: Camera,
    rule: ExposureRule,
    start_exposure_s: float,
    candidates_s: Sequence[float] | None = None,
    step_down: float = 4.0,
    backoff: float = 0.9,
    quantise: Callable[[float], float] | None = None,
) -> ExposureChoice:
    """Short test series at the current light: preview, predict, verify with a real shot.

    The caller turns on the brightest planned light first. A preview that saturates too much is
    retaken ``step_down`` times shorter; a predicted exposure that fails verification is
    shortened by ``backoff`` (or to the next shorter candidate) towards the preview's. At most
    ``rule.max_attempts`` shots are taken; if none verifies, the longest good shot is chosen.

    With ``candidates_s``, a ``start_exposure_s`` the camera does not offer starts the series
    at the offered exposure nearest it in stops, within the rule's range. It had raised a
    ValueError: ``rti-rig run --auto-exposure`` on a DSLR without the config's exposure in its
    shutter list (0.125 s on a body in 1/2-stop steps) stopped before its first test shot with
    "unexpected ValueError … please report it", although metering exists to choose the
    exposure from the camera's own list.

    ``quantise`` (see :class:`_Quantised`) rounds each requested exposure down to one the
    camera takes exactly; the choice is then always a shot's own exposure.
    """
    if quantise is not None:
        camera = _Quantised(camera, quantise)
    if step_down <= 1:
        raise ValueError("step_down must exceed 1")
    if not 0 < backoff < 1:
        raise ValueError("backoff must lie in (0, 1)")
    if candidates_s is not None:
        start_exposure_s = _nearest_offered(start_exposure_s, rule, candidates_s)
    series: list[Frame] = []
    frame = _shot(camera, start_exposure_s, series)
    while True:
        if frame.saturated_fraction > rule.max_saturated_fraction:
            shorter = _shorter(frame.exposure_s / step_down, rule, candidates_s)
            if shorter >= frame.exposure_s or len(series) >= rule.max_attempts:
                break
            frame = _shot(camera, shorter, series)
            continue
        choice = choose_exposure(frame, rule, candidates_s)
        if np.isclose(choice.exposure_s, frame.exposure_s, rtol=1e-9):
            return _measured(choice, frame, series)
        # Verify with a real shot. Noise can push a few more pixels over white than the preview
        # predicted; back off towards the (good) preview exposure until one verifies.
        target = choice.exposure_s
        while len(series) < rule.max_attempts and target > frame.exposure_s:
            check = _shot(camera, target, series)
            if check.saturated_fraction <= rule.max_saturated_fraction:
                return _measured(choice, check, series)
            target = _backoff(target, frame.exposure_s, backoff, candidates_s)
        break
    return choose_from_series(series, rule)


def recheck_exposure(
    camera: Camera,
    rule: ExposureRule,
    exposure_s: float,
    candidates_s: Sequence[float] | None = None,
    step_down: float = 4.0,
    backoff: float = 0.9,
    quantise: Callable[[float], float] | None = None,
) -> tuple[ExposureChoice | None, tuple[float, ...]]:
    """Does ``exposure_s``, chosen at another light, keep within ``rule`` at the current one?

    Why: on a dome whose LEDs differ, the light metered first need not be the brightest, and
    one shot per further light is the least that tells. Returns a choice and the exposures of
    the shots taken here. The choice is None when that shot keeps within the rule, headroom
    included. Where this light is brighter it is the longest exposure up to ``exposure_s`` that
    keeps within the rule here: predicted from that shot when it is within the limit (a
    shorter exposure only darkens what was measured), else from a test series from
    ``step_down`` times shorter (:func:`meter_exposure`, never longer than ``exposure_s``).
    ``quantise`` as for :func:`meter_exposure`; a predicted choice is rounded down by it too."""
    if quantise is not None:
        camera = _Quantised(camera, quantise)
    series: list[Frame] = []
    frame = _shot(camera, exposure_s, series)
    limit = rule.max_saturated_fraction
    if (
        frame.saturated_fraction <= limit
        and predicted_saturated_fraction(frame, exposure_s, rule.headroom) <= limit
    ):
        return None, (frame.exposure_s,)
    capped = rule.model_copy(update={"max_exposure_s": exposure_s})
    if frame.saturated_fraction <= limit:
        choice = choose_exposure(frame, capped, candidates_s)
        if quantise is not None:  # shorter than predicted: never more saturated
            choice = replace(choice, exposure_s=quantise(choice.exposure_s))
        return choice, (frame.exposure_s,)
    start = _shorter(exposure_s / step_down, capped, candidates_s)
    choice = meter_exposure(camera, capped, start, candidates_s, step_down, backoff)
    tested = (frame.exposure_s, *choice.test_exposures_s)
    return replace(choice, test_exposures_s=tested), tested


class _Quantised:
    """``camera`` asked only for exposures it takes exactly: each request rounded down by
    ``quantise`` (e.g. a UVC camera's whole ``exposure_unit_s`` steps).

    Why: the metering solves for any exposure in its range and steps a saturated preview down
    4 times at a time (0.05 s, 0.0125 s, 0.0031 s, 0.00078 s): a UVC camera set in 100 µs
    units refuses one more than ``exposure_tolerance`` from a whole unit, and a bright object
    stopped ``run --auto-exposure`` with "exposure 0.000775 s is not a whole number of
    0.0001 s units …; choose a representable exposure", an exposure the user never chose.
    Rounded down, a shot never saturates more than the one asked for."""

    def __init__(self, camera: Camera, quantise: Callable[[float], float]) -> None:
        self._camera, self._quantise = camera, quantise
        self.name = camera.name

    def capture(self, exposure_s: float) -> Frame:
        return self._camera.capture(self._quantise(exposure_s))

    def __getattr__(self, name: str) -> Any:
        return getattr(self._camera, name)


def _shot(camera: Camera, exposure_s: float, series: list[Frame]) -> Frame:
    frame = camera.capture(exposure_s)
    if frame.exposure_s <= 0:
        raise CaptureError(camera.name, "frame has no exposure time; cannot meter", "meter")
    series.append(frame)
    return frame


def _nearest_offered(exposure_s: float, rule: ExposureRule, candidates_s: Sequence[float]) -> float:
    """The candidate nearest ``exposure_s`` in stops, preferring those in the rule's range."""
    offered = [float(c) for c in candidates_s if c > 0]
    if not offered:
        raise ValueError("candidates_s holds no exposure")
    ranged = [c for c in offered if rule.min_exposure_s <= c <= rule.max_exposure_s] or offered
    return min(ranged, key=lambda c: abs(np.log(c / exposure_s)))


def _shorter(target: float, rule: ExposureRule, candidates_s: Sequence[float] | None) -> float:
    if candidates_s is None:
        return max(target, rule.min_exposure_s)
    ok = [c for c in candidates_s if rule.min_exposure_s <= c <= target]
    if ok:
        return max(ok)
    return min(c for c in candidates_s if c >= rule.min_exposure_s)


def _backoff(
    target: float, floor: float, factor: float, candidates_s: Sequence[float] | None
) -> float:
    if candidates_s is None:
        return max(target * factor, floor)
    shorter = [c for c in candidates_s if floor <= c < target]
    return max(shorter) if shorter else floor


def _measured(choice: ExposureChoice, frame: Frame, series: list[Frame]) -> ExposureChoice:
    return ExposureChoice(
        exposure_s=frame.exposure_s,
        satisfied=True,
        predicted_saturated_fraction=choice.predicted_saturated_fraction,
        method="test-series",
        reason=choice.reason + f"; verified: {frame.saturated_fraction:.4%} saturated",
        rule=choice.rule,
        measured_saturated_fraction=frame.saturated_fraction,
        test_exposures_s=tuple(f.exposure_s for f in series),
    )
