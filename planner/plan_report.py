"""The evidence behind a plan (:class:`PlanReport`): what the planner measured, assumed and
expects, for the CLI to print and the session to keep beside the schedule."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from rti_rig.planner.light_origin import LightOrigin
from rti_rig.planner.objectives import GRAZING_COS
from rti_rig.planner.pixel_bins import GRAZING_DEG
from rti_rig.planner.tilt_guard import (
    MAX_GUARD_DEG,
    NEED_LIT,
    REPORT_MAX_DEG,
    SOLVABLE_COND,
    TILT_STEP_DEG,
)

#: The elevation above the object's plane below which a light counts as grazing (the
#: objectives' ``GRAZING_COS``), as a plan says it.
GRAZING_COS_DEG = math.degrees(math.asin(GRAZING_COS))
#: What the tilt lines mean by lights that "determine a normal" (:func:`~rti_rig.planner.
#: tilt_guard.solvable`): a count of facing lights alone was said before, and three facing
#: lights on one great circle solve nothing.
DETERMINE_RULE = (
    f"{NEED_LIT} or more lights {GRAZING_COS_DEG:.0f}° or more above the object's plane and not "
    f"nearly on one great circle, their condition number at most {SOLVABLE_COND:g} as the fit "
    "asks of a pixel's lights"
)


@dataclass
class PlanReport:
    """Evidence behind a plan, for the CLI to print and the session to keep."""

    method: str
    objective: str
    n: int
    rig: str
    candidates: int
    min_elevation_deg: float
    max_elevation_deg: float = 90.0
    preview_shape: tuple[int, ...] | None = None
    planning_shape: tuple[int, ...] | None = None
    preview_light_az_el_deg: tuple[float, float] | None = None
    #: where the preview's light came from (None: no preview was evaluated)
    preview_light_origin: LightOrigin | None = None
    #: the origin in words, for the reader (the app's sentence; without one, the origin's name)
    preview_light_source: str | None = None
    #: why the zenith was assumed for the preview's light, no direction being had from it
    preview_light_why_zenith: str | None = None
    relief_source: str | None = None
    relief_scale: float | None = None
    shading_explained_r2: float | None = None
    rms_tilt_deg: float | None = None
    p90_tilt_deg: float | None = None
    highlight_hint: float | None = None
    nonfinite_relief_repaired: int = 0
    signal_noise: float = 0.0
    material: str = "auto"
    model: str | None = None
    expected: dict[str, float] = field(default_factory=dict)
    expected_meaning: str | None = None
    start_layout: str | None = None
    swaps: int | None = None
    #: why the method kept its start layout without searching (``optimal`` at 3 lights), for
    #: the plan's one-line summary to say what was done instead of "(optimal, normals)"
    kept_layout_why: str | None = None
    #: pixel rows the objective scores and the rows the exchange search swept, when it swept a
    #: binned stand-in (:mod:`rti_rig.planner.pixel_bins`)
    search_pixels: tuple[int, int] | None = None
    #: the global tilt (degrees) under which the exchange kept lights that determine a normal
    #: (:data:`DETERMINE_RULE`), as the most tilt-robust even layout compared did, up to a cap
    #: (:mod:`rti_rig.planner.tilt_guard`); None when no guard applied
    guarded_tilt_deg: float | None = None
    #: the largest global tilt of the object's plane (degrees, every direction, checked up to
    #: :data:`~rti_rig.planner.tilt_guard.REPORT_MAX_DEG`) under which the written lights
    #: still determine a normal (:data:`DETERMINE_RULE`; -1: not even level); and the same of
    #: the even layout of as many lights from the user's floor (``--method uniform``'s): every
    #: plan says it, since one image cannot show a global tilt and a layout that loses the
    #: plane solves nothing
    tilt_tolerance_deg: float | None = None
    even_tilt_tolerance_deg: float | None = None
    #: how many of the written lights face the object's plane, level, past grazing: where they
    #: determine no normal even level, it says whether too few face it or those that do lie on
    #: one great circle (None: not counted, and the line names both)
    level_facing_lights: int | None = None
    kmeans_distinct_normals: int | None = None
    notes: list[str] = field(default_factory=list)
    seconds: float = 0.0
    #: the arm's stop-order search (after the lights are chosen), None on a dome: ``seconds``
    #: is the choosing alone
    order_seconds: float | None = None

    def _tilt_line(self, tolerance: float, even: float | None) -> str:
        """What the written lights keep of a global tilt, and what the even layout would."""
        said = _kept_by_lights(tolerance, self.level_facing_lights)
        if even is not None and even > tolerance and self.method != "uniform":
            said += (
                f"; the even layout of {self.n} lights (--method uniform) does so "
                f"{_kept_phrase(even)}: one image cannot show a global tilt"
            )
        return said

    def _guarded_line(self, guarded: float) -> str:
        """What ``optimal``'s tilt guard kept, and the written lights' own tolerance where it
        is more (the guard asks at most :data:`~rti_rig.planner.tilt_guard.MAX_GUARD_DEG`)."""
        why = (
            "the most the guard asks (an even layout compared may keep more)"
            if guarded >= MAX_GUARD_DEG
            else "as the most tilt-robust of the even layouts compared did"
        )
        own = self.tilt_tolerance_deg
        mine = (
            f"; the written lights do so {_kept_phrase(own)}"
            if own is not None and own > guarded
            else ""
        )
        return (
            f"kept lights that determine a normal ({DETERMINE_RULE}) if the object is "
            f"tilted up to {guarded:g}° in any direction, {why}{mine}: one image cannot show a "
            "global tilt, so layouts that would lose the plane to it were not taken for a lower "
            "expected error"
        )

    def light_said(self) -> str | None:
        """The preview light's origin as the reader is told it."""
        if self.preview_light_source is not None or self.preview_light_origin is None:
            return self.preview_light_source
        return self.preview_light_origin.value

    def to_dict(self) -> dict[str, Any]:
        """The report as saved beside the schedule: the origin is kept as its words (the
        string field readers of saved plans have), not as the enum."""
        d = asdict(self)
        del d["preview_light_origin"]
        d["preview_light_source"] = self.light_said()
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in d.items()}

    def lines(self) -> list[str]:
        """Human-readable summary, one fact per line."""
        out = [f"method {self.method}, objective {self.objective}, {self.n} lights on {self.rig}"]
        if self.max_elevation_deg < 90.0:
            out.append(
                f"lights between {self.min_elevation_deg:g}° and {self.max_elevation_deg:g}° "
                "elevation (none near the camera axis)"
            )
        if self.preview_light_az_el_deg is not None:
            az, el = self.preview_light_az_el_deg
            out.append(f"preview light az {az:.1f}°, el {el:.1f}° ({self.light_said()})")
        if self.relief_source and self.shading_explained_r2 is None:
            out.append(f"relief: {self.relief_source}")
        elif self.relief_source:
            out.append(
                f"relief from {self.relief_source}: RMS tilt {self.rms_tilt_deg:.1f}°, "
                f"90th percentile {self.p90_tilt_deg:.1f}°, shading explained "
                f"R²={self.shading_explained_r2:.2f}"
            )
        if self.model:
            out.append(f"relighting model assumed: {self.model}")
        if self.signal_noise > 0:
            out.append(
                f"noise modelled: {100 * self.signal_noise:g} % of the signal on top of the "
                "additive noise (in the tests it cost accuracy on a steeply tilted flat object, "
                "and on brushed steel from 12 lights: give --signal-noise 0 for such objects; "
                "docs/research/planner.md)"
            )
        if self.expected and self.expected_meaning:
            parts = ", ".join(f"{k} {v:#.4g}" for k, v in self.expected.items())
            out.append(f"{self.expected_meaning}: {parts}")
        if self.search_pixels is not None:
            every, binned = self.search_pixels
            out.append(
                f"searched on {binned} binned pixel rows of {every} (nearly equal normals, same "
                f"shadows from lights above {GRAZING_DEG:g}°); the expected errors above are on "
                f"all {every}"
            )
        if self.guarded_tilt_deg is not None:
            out.append(self._guarded_line(self.guarded_tilt_deg))
        elif self.tilt_tolerance_deg is not None:
            out.append(self._tilt_line(self.tilt_tolerance_deg, self.even_tilt_tolerance_deg))
        out.extend(self.notes)
        if self.order_seconds is None:
            out.append(f"planned in {self.seconds:.2f} s")
        else:
            out.append(
                f"planned in {self.seconds + self.order_seconds:.2f} s ({self.seconds:.2f} s "
                f"choosing the lights, {self.order_seconds:.2f} s ordering the arm's stops)"
            )
        return out


def _kept_phrase(tolerance: float) -> str:
    """How far a tilt leaves lights that determine a normal, after "does so"."""
    if tolerance < 0.0:
        return "not even level"
    if tolerance == 0.0:
        return "only while it is level"
    if tolerance >= REPORT_MAX_DEG:
        return f"at {REPORT_MAX_DEG:g}° of tilt in any direction (as far as checked)"
    return f"up to {tolerance:g}° of tilt in any direction"


def _kept_by_lights(tolerance: float, facing: int | None = None) -> str:
    """The written lights' tolerance as a sentence's start (``facing``: how many face the
    level object's plane past grazing, to say why a tolerance of -1)."""
    high = f"{GRAZING_COS_DEG:.0f}° or more above the object's plane"
    if tolerance < 0.0 and facing is not None and facing < NEED_LIT:
        few = {0: "none of these lights stands", 1: "only 1 of these lights stands"}.get(
            facing, f"only {facing} of these lights stand"
        )
        return (
            f"{few} {high} even with the object level, and a normal needs {NEED_LIT}: its "
            "normals rest on grazing light"
        )
    if tolerance < 0.0 and facing is not None:
        return (
            f"the {facing} of these lights that stand {high} lie nearly on one great circle "
            f"(their condition number above {SOLVABLE_COND:g}, more than the fit allows a "
            "pixel's lights): they determine no normal even with the object level"
        )
    if tolerance < 0.0:
        return (
            f"these lights do not determine a normal ({DETERMINE_RULE}) even with the object "
            f"level: fewer than {NEED_LIT} stand that high, or those that do lie nearly on one "
            "great circle, and its normals rest on grazing light or on too few directions"
        )
    if tolerance == 0.0:
        return (
            f"these lights determine a normal ({DETERMINE_RULE}) only while the object is "
            f"level: a {TILT_STEP_DEG:g}° tilt in some direction leaves too few"
        )
    if tolerance >= REPORT_MAX_DEG:
        return (
            f"these lights determine a normal ({DETERMINE_RULE}) even if the object is tilted "
            f"{REPORT_MAX_DEG:g}° in any direction (as far as checked)"
        )
    return (
        f"these lights determine a normal ({DETERMINE_RULE}) if the object is tilted up to "
        f"{tolerance:g}° in any direction, not beyond"
    )
