"""Where a rig can put light, as plain data the planner can use without any hardware.

A dome offers a finite set of calibrated LED directions; an arm offers a continuous band of
elevations minus a keep-out cone around the camera. Both come from the rig config.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.errors import ScheduleError
from rti_rig.core.fit_minimums import NORMAL_MIN_LIGHTS, PLAN_DEFAULT_LIGHTS
from rti_rig.core.geometry import (
    angle_between_deg,
    az_el_from_direction,
    direction_from_az_el,
    even_layout,
    triad_within_azimuths,
)

#: Two LEDs closer than this (degrees) are one LED listed twice: a real LED is several tenths of a
#: degree across as seen from the object, and `.lp` files resolve ~0.0001°.
COINCIDENT_LED_DEG = 0.1


def coincident_leds(directions: ArrayLike) -> tuple[int, int] | None:
    """The first pair ``(i, j)``, ``i < j``, of LEDs sharing a direction, or ``None``.

    Why it matters: the planner would treat such a pair as two lights and may choose both, a
    plan cannot tell them apart when it is run, and two images of one direction add no
    information. Callers name the file or key, since that is what the user has to fix.
    """
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    if len(d) < 2:
        return None
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    close = np.triu(d @ d.T >= np.cos(np.radians(COINCIDENT_LED_DEG)), k=1)
    pairs = np.argwhere(close)
    return None if pairs.size == 0 else (int(pairs[0][0]), int(pairs[0][1]))


def repeated_directions(directions: ArrayLike) -> list[list[int]]:
    """The groups (each in order, of two or more) of lights sharing a direction within
    :data:`COINCIDENT_LED_DEG`, as :func:`coincident_leds` judges a pair: an acquisition may
    repeat a light, and a fit has one direction the fewer for each repeat."""
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    if len(d) < 2:
        return []
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    close = d @ d.T >= np.cos(np.radians(COINCIDENT_LED_DEG))
    seen: set[int] = set()
    groups = []
    for i in range(len(d)):
        if i in seen:
            continue
        group = [int(j) for j in np.flatnonzero(close[i]) if j >= i and j not in seen]
        seen.update(group)
        if len(group) > 1:
            groups.append(group)
    return groups


def default_led_name(index: int) -> str:
    """The name a dome config without an ``lp_file`` gives LED ``index`` (``led_036``): a
    machine-readable id kept in plans and manifests (a step's ``label``), never what a user
    is told (they are told "LED 36", as ``check`` and the dome's errors count LEDs)."""
    return f"led_{index:03d}"


def direction_said(direction: ArrayLike) -> str:
    """Where a light comes from, as every word to a user says it: ``az 112.5°, el 55.0°``
    (one decimal: a dome's LEDs are degrees apart, an arm's ticks a tenth of one)."""
    az, el = (float(v) for v in az_el_from_direction(np.asarray(direction, dtype=np.float64)))
    return f"az {az:.1f}°, el {el:.1f}°"


def led_fields(index: int, direction: ArrayLike, name: str | None = None) -> str:
    """Dome LED ``index`` as a list inside the caller's own parentheses:
    ``LED 36, az 112.5°, el 55.0°``. A name the user gave it (a dome ``.lp``'s image name) is
    said beside the number (``LED 36, led_36.jpg, az …``); the dome's own id for it
    (:func:`default_led_name`, ``led_036``) is not, as it names nothing the user wrote."""
    given = f", {name}" if name and name != default_led_name(index) else ""
    return f"LED {index}{given}, {direction_said(direction)}"


def led_said(index: int, direction: ArrayLike, name: str | None = None) -> str:
    """Dome LED ``index`` as a user is told of it: ``LED 36 (az 112.5°, el 55.0°)``, or
    ``LED 36 (led_36.jpg, az 112.5°, el 55.0°)`` with a name the user gave it.

    Why: words had named a ring dome's LED "LED 36 (led_036)", the id the dome keeps in plans
    and manifests, which tells the user nothing about which LED to look at; its direction
    does (the preview's note and a refused step already said it so)."""
    number, _, rest = led_fields(index, direction, name).partition(", ")
    return f"{number} ({rest})"


@dataclass(frozen=True)
class LampGeometry:
    """How far the lamps are from the object and how wide the frame's field is on it (mm).

    Why: a lamp at a few times the field's width lights each pixel from its own direction and
    at its own distance, while every fit (this project's, relight's, RTIBuilder's) reads one
    direction per light. What that costs the normals depends on these two figures only; the
    adaptive stop's estimate renders it (``planner.adaptive_bias.NearLamps``)."""

    distance_mm: float
    field_width_mm: float

    def __post_init__(self) -> None:
        if not (self.distance_mm > 0 and self.field_width_mm > 0):
            raise ValueError(
                f"lamp distance {self.distance_mm} mm and field width {self.field_width_mm} mm "
                "must both be > 0"
            )

    def record(self) -> dict[str, float]:
        """As a session's settings record it."""
        return {"distance_mm": self.distance_mm, "field_width_mm": self.field_width_mm}


@dataclass(frozen=True, eq=False)
class DomeGeometry:
    """A dome: LED ``i`` lights from ``directions[i]`` and is called ``names[i]``."""

    directions: NDArray[np.float64]
    names: tuple[str, ...]

    def __post_init__(self) -> None:
        d = np.asarray(self.directions, dtype=np.float64).reshape(-1, 3)
        d.setflags(write=False)
        object.__setattr__(self, "directions", d)
        object.__setattr__(self, "names", tuple(self.names))
        if len(self.names) != len(d):
            raise ValueError("one name per LED is needed")

    @property
    def count(self) -> int:
        return len(self.directions)

    def led_said(self, index: int) -> str:
        """LED ``index`` as words say it (:func:`led_said`): its number and direction."""
        return led_said(index, self.directions[index], self.names[index])

    def led_fields(self, index: int) -> str:
        """LED ``index`` as a list inside the caller's parentheses (:func:`led_fields`)."""
        return led_fields(index, self.directions[index], self.names[index])

    def nearest_led(self, direction: ArrayLike) -> tuple[int, float]:
        """Index of the LED closest to ``direction`` and the angle to it in degrees."""
        ang = angle_between_deg(self.directions, np.asarray(direction, dtype=np.float64))
        i = int(np.argmin(ang))
        return i, float(ang[i])


#: How far outside an elevation band (degrees) a light may lie and still be in it: an `.lp`
#: keeps six decimals, which move a light on the band's edge by up to ~3e-5° (a 10° ring read
#: from a dome's `.lp` lies at 9.99998°). Far below any LED's or pose's precision. Why one
#: value for every band test: the planner and ``run`` compared with 1e-9°, so ``run
#: --min-elevation-deg 10`` on a dome described by its `.lp` dropped the whole 10° ring
#: without a word, while ``run --plan`` with the same band (1e-3°) took it.
BAND_SLACK_DEG = 1e-3


def in_band(elevations: ArrayLike, low_deg: float, high_deg: float = 90.0) -> NDArray[np.bool_]:
    """Which of ``elevations`` (degrees, an array) lie from ``low_deg`` to ``high_deg``, to
    within :data:`BAND_SLACK_DEG`."""
    el = np.asarray(elevations, dtype=np.float64)
    return (el >= low_deg - BAND_SLACK_DEG) & (el <= high_deg + BAND_SLACK_DEG)


def hint_light_count(geometry: object, low_deg: float = 0.0, high_deg: float = 90.0) -> int:
    """How many lights a hint's ``plan`` or ``run --lights`` command asks for:
    :data:`PLAN_DEFAULT_LIGHTS`, or fewer on a dome with fewer LEDs between ``low_deg`` and
    ``high_deg`` of elevation (at least :data:`NORMAL_MIN_LIGHTS`, what a plan needs); any
    other rig (an arm) has no such limit.

    Why: ``--lights N`` pasted as printed was refused as not a whole number, and a fixed
    ``--lights 12`` on a dome of 8 LEDs (or 8 in the band) was refused as more lights than it
    has; the preview computed the real count and the other hints did not."""
    if not isinstance(geometry, DomeGeometry):
        return PLAN_DEFAULT_LIGHTS
    _, elevations = az_el_from_direction(geometry.directions)
    held = int(in_band(elevations, low_deg, high_deg).sum())
    return max(NORMAL_MIN_LIGHTS, min(PLAN_DEFAULT_LIGHTS, held))


#: How far past an arm's limit (degrees) a direction may lie and count as on it: an `.lp`
#: keeps six decimals, which put a light planned exactly on a limit up to ~1e-4° either side
#: (a plan at the 15° keep-out edge was refused as "15.00° from the camera axis, inside the
#: 15° keep-out cone … made for another rig"). Far below a servo tick (0.088°): the driver
#: rounds such a pose onto the limit's own tick, and its tick gate stays exact.
LIMIT_SLACK_DEG = 1e-3


@dataclass(frozen=True)
class ArmGeometry:
    """An arm's reachable band of light directions and its parking pose."""

    min_elevation_deg: float
    max_elevation_deg: float
    keep_out_half_angle_deg: float
    park_azimuth_deg: float
    park_elevation_deg: float
    #: Azimuth range of the arm's base joint, in (-180, 180] terms (a cable stops a full turn).
    min_azimuth_deg: float = -180.0
    max_azimuth_deg: float = 180.0
    #: The elevation joint's upper limit as the config writes it, when the keep-out cone stops
    #: the arm below it (``max_elevation_deg`` is then ``90 - keep_out_half_angle_deg``); None
    #: otherwise. Why: a note said "its elevation limits 0°..75°" of a config saying 90°, as if
    #: the config had been misread. Only words use it: it is left out of comparisons and of the
    #: rig's identity (the reach itself is unchanged).
    configured_max_elevation_deg: float | None = field(default=None, compare=False)

    @property
    def park_direction(self) -> NDArray[np.float64]:
        return direction_from_az_el(self.park_azimuth_deg, self.park_elevation_deg)

    def unreachable_reason(self, direction: ArrayLike) -> str | None:
        """``None`` when the arm may go to ``direction``, else the limit it would break."""
        d = np.asarray(direction, dtype=np.float64)
        _, el = az_el_from_direction(d)
        el = float(el)
        off_axis = float(angle_between_deg(d, (0.0, 0.0, 1.0)))
        if off_axis < self.keep_out_half_angle_deg - LIMIT_SLACK_DEG:
            return (
                f"direction is {off_axis:.2f}° from the camera axis, inside the "
                f"{self.keep_out_half_angle_deg:g}° keep-out cone"
            )
        if el < self.min_elevation_deg - LIMIT_SLACK_DEG:
            return f"elevation {el:.2f}° is below the arm's minimum {self.min_elevation_deg:g}°"
        if el > self.max_elevation_deg + LIMIT_SLACK_DEG:
            return f"elevation {el:.2f}° is above the arm's maximum {self.max_elevation_deg:g}°"
        az = float(az_el_from_direction(d)[0])
        az = az - 360.0 if az > 180.0 else az
        if (
            not self.min_azimuth_deg - LIMIT_SLACK_DEG
            <= az
            <= self.max_azimuth_deg + LIMIT_SLACK_DEG
        ):
            return (
                f"azimuth {az:.2f}° is outside the arm's range "
                f"[{self.min_azimuth_deg:g}°, {self.max_azimuth_deg:g}°]"
            )
        return None

    def reachable(self, directions: ArrayLike) -> NDArray[np.bool_]:
        """For each of ``directions`` (M, 3): may the arm go there? The limits of
        :meth:`unreachable_reason`, checked for all at once (a planner checks hundreds)."""
        d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
        az, el = az_el_from_direction(d)
        off_axis = angle_between_deg(d, np.array([0.0, 0.0, 1.0]))
        az = np.where(az > 180.0, az - 360.0, az)
        return (
            (off_axis >= self.keep_out_half_angle_deg - LIMIT_SLACK_DEG)
            & (el >= self.min_elevation_deg - LIMIT_SLACK_DEG)
            & (el <= self.max_elevation_deg + LIMIT_SLACK_DEG)
            & (az >= self.min_azimuth_deg - LIMIT_SLACK_DEG)
            & (az <= self.max_azimuth_deg + LIMIT_SLACK_DEG)
        )

    def elevation_band(self, min_elevation_deg: float = 0.0) -> tuple[float, float]:
        """The reachable elevations (degrees) at or above a floor; ScheduleError if none."""
        lo = max(min_elevation_deg, self.min_elevation_deg)
        hi = min(self.max_elevation_deg, 90.0 - self.keep_out_half_angle_deg)
        if lo >= hi:
            raise ScheduleError(
                f"elevation floor {min_elevation_deg:g}° leaves no reachable band "
                f"(the arm reaches {self.min_elevation_deg:g}°..{hi:g}°): lower it below "
                f"{hi:g}° (--min-elevation-deg)"
            )
        return lo, hi

    def homogeneous(self, n: int, min_elevation_deg: float = 0.0) -> NDArray[np.float64]:
        """``n`` directions spread evenly over the reachable band and the reachable azimuths.

        The even layout's azimuths (-180°..180°) are mapped linearly onto the arm's azimuth
        range, so that the spread stays even within it. Why: they had been moved onto the
        nearest limit instead, so an arm turning ±170° lit every light of the 20° it cannot
        reach at exactly ±170° (two or three lights of 24 at one place, a gap beside them).
        Three lights are the triad, placed within the range (:func:`triad_within_azimuths`)."""
        if n <= 0:
            raise ScheduleError(f"--lights must be at least 1, got {n}")
        lo, hi = self.elevation_band(min_elevation_deg)
        if n == 3:  # mapped linearly, the triad's three lights would close up on one ring
            return triad_within_azimuths(self.min_azimuth_deg, self.max_azimuth_deg, lo, hi)
        return self.mapped_onto_range(even_layout(n, lo, hi))

    def mapped_onto_range(self, directions: ArrayLike) -> NDArray[np.float64]:
        """``directions`` with their azimuths (-180°..180°) mapped linearly onto the arm's
        azimuth range, each keeping its elevation (as they are on an arm turning all round)."""
        az, el = az_el_from_direction(np.asarray(directions, dtype=np.float64))
        a = np.where(az > 180.0, az - 360.0, az)
        span = self.max_azimuth_deg - self.min_azimuth_deg
        if span < 360.0:
            a = self.min_azimuth_deg + (a + 180.0) * (span / 360.0)
        return direction_from_az_el(a, el)

    def clamp_azimuth(self, direction: ArrayLike) -> NDArray[np.float64]:
        """``direction`` with its azimuth moved to the nearest end of the arm's range if outside."""
        az, el = az_el_from_direction(np.asarray(direction, dtype=np.float64))
        a = float(az) - 360.0 if float(az) > 180.0 else float(az)
        a = min(max(a, self.min_azimuth_deg), self.max_azimuth_deg)
        return direction_from_az_el(a, float(el))


RigGeometry = DomeGeometry | ArmGeometry
