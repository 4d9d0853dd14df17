"""Homogeneous light layouts: the baseline every smarter plan must beat.

For a dome, "homogeneous" means choosing ``n`` of its LEDs that cover the hemisphere (above an
optional elevation floor) as evenly as possible, without repeats: ideal equal-area directions
(for three lights the orthogonal triad, :func:`~rti_rig.core.geometry.even_layout`) are matched
one-to-one to LEDs by minimum total angle (an optimal assignment, not greedy snapping, which can
pick the same LED twice or leave gaps). For an arm, the ideal directions are used directly
within its reachable band.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import angle_between_deg, az_el_from_direction, even_layout
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry, in_band
from rti_rig.core.schedule import LightSchedule


def band_text(min_elevation_deg: float, max_elevation_deg: float) -> str:
    """ " at or above F° elevation" / " between F° and C° elevation" / "" for the full dome."""
    if max_elevation_deg < 90.0:
        return f" between {min_elevation_deg:g}° and {max_elevation_deg:g}° elevation"
    return f" at or above {min_elevation_deg:g}° elevation" if min_elevation_deg > 0 else ""


def count_in_band_text(
    count: int,
    band: str,
    elevations: NDArray[np.float64],
    one: str = "LED",
    where: str = "its LEDs",
) -> str:
    """What a rig has in an elevation band, for a refusal of too many lights: "only 6 LEDs at or
    above 65° elevation", or, with none there, where its lights do stand ("no LED at or above
    80° elevation (its LEDs stand between 10° and 70°)"): the elevations to widen the band to.
    Why: "only 0 LEDs at or above 80°" had been said of a dome whose highest LED is at 70°."""
    if count:
        return f"only {count} {one}{'s' if count != 1 else ''}{band}"
    lo, hi = float(elevations.min()), float(elevations.max())
    return f"no {one}{band} ({where} stand between {lo:.3g}° and {hi:.3g}°)"


def band_run_options(lights: int, min_elevation_deg: float, max_elevation_deg: float) -> str:
    """``--lights N`` and the ``--min/--max-elevation-deg`` (those not at their defaults) of a
    planned run that keeps to a band: the advice of a refusal that sends the user to one."""
    out = f"--lights {lights}"
    if min_elevation_deg != 0.0:
        out += f" --min-elevation-deg {min_elevation_deg:g}"
    if max_elevation_deg != 90.0:
        out += f" --max-elevation-deg {max_elevation_deg:g}"
    return out


def select_uniform_leds(
    dome: DomeGeometry,
    n: int,
    min_elevation_deg: float = 0.0,
    azimuth_offset_deg: float = 0.0,
    max_elevation_deg: float = 90.0,
    fewest: int = 1,
) -> NDArray[np.intp]:
    """Indices (ascending) of ``n`` LEDs spread evenly between ``min_elevation_deg`` and
    ``max_elevation_deg``.

    ``azimuth_offset_deg`` turns the ideal layout about the vertical before it is matched to
    LEDs: every offset is an equally homogeneous layout, and the spread of their errors on a
    real object is the luck a homogeneous layout's arbitrary orientation carries (the real-data
    benchmark reports it).
    """
    if n <= 0:
        raise ScheduleError(f"--lights must be at least 1, got {n}")
    _, el = az_el_from_direction(dome.directions)
    candidates = np.flatnonzero(in_band(el, min_elevation_deg, max_elevation_deg))
    if n > len(candidates):
        band = band_text(min_elevation_deg, max_elevation_deg)
        # ``fewest``: the smallest --lights the caller takes (a plan's 3: "use --lights 1 or
        # fewer" had been advised where --lights 1 is refused)
        fewer = f"use --lights {len(candidates)} or fewer" if len(candidates) >= fewest else ""
        if max_elevation_deg < 90.0 or min_elevation_deg > 0:
            widen = "widen --min-elevation-deg / --max-elevation-deg"
            fewer = f"{fewer} or {widen}" if fewer else widen
        if not fewer:  # no fewer lights will do and there is no band to widen
            fewer = f"a plan needs at least {fewest} lights: use a rig with more"
        has = count_in_band_text(len(candidates), band, el)
        raise ScheduleError(f"asked for {n} lights but the dome has {has}; {fewer}")
    if n == len(candidates):
        return np.sort(candidates)
    lo = max(min_elevation_deg, float(el[candidates].min()))
    hi = float(el[candidates].max())
    ideal = even_layout(n, lo, hi) if hi > lo else even_layout(n, 0.0, 90.0)
    if azimuth_offset_deg:
        t = np.radians(azimuth_offset_deg)
        c, s = np.cos(t), np.sin(t)
        ideal = ideal @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T
    # scipy.optimize takes 0.3 s to import: an arm's plan (and `--help`) never needs it
    from scipy.optimize import linear_sum_assignment

    cost = angle_between_deg(ideal[:, None, :], dome.directions[candidates][None, :, :])
    _, cols = linear_sum_assignment(cost)
    return np.sort(candidates[cols])


def arm_below(arm: ArmGeometry, max_elevation_deg: float) -> ArmGeometry:
    """The arm as planning sees it under an elevation ceiling: its band cut at the ceiling
    (its reach, limits and park pose otherwise unchanged)."""
    if max_elevation_deg >= arm.max_elevation_deg:
        return arm
    if max_elevation_deg <= arm.min_elevation_deg:
        raise ScheduleError(
            f"--max-elevation-deg {max_elevation_deg:g} is at or below the arm's lowest "
            f"elevation ({arm.min_elevation_deg:g}°): no light is left; raise it"
        )
    return replace(arm, max_elevation_deg=max_elevation_deg)


def arm_band_note(
    arm: ArmGeometry,
    min_elevation_deg: float,
    max_elevation_deg: float,
    *,
    min_given: bool = False,
    max_given: bool = False,
) -> str | None:
    """What an elevation band asked for (``--min/--max-elevation-deg``) became on ``arm``,
    when part of it is beyond the arm's reach; None when the band is used as given (or not
    given at all: 0..90 means every elevation the rig offers).

    Why: the layout was spread over the reachable part alone, silently: on an arm reaching
    75°, "--min-elevation-deg 70 --max-elevation-deg 90" gave lights between 70° and 75° and
    nothing said the top 15° of the band had been cut. ``min_given``/``max_given``: that bound
    was typed (its option on the command line): "--max-elevation-deg 90" typed on that arm had
    been cut to 75° in silence, as the default is. The note names the options typed only: it
    had said "--min-elevation-deg 0 --max-elevation-deg 90" of "--max-elevation-deg 90" alone,
    an option the user never gave. A bound not typed but not at its default (a caller's own
    band) is named too."""
    given = min_given or max_given
    if (min_elevation_deg, max_elevation_deg) == (0.0, 90.0) and not given:
        return None
    top = min(arm.max_elevation_deg, 90.0 - arm.keep_out_half_angle_deg)
    lo = max(min_elevation_deg, arm.min_elevation_deg)
    hi = min(max_elevation_deg, top)
    if lo >= hi or (lo, hi) == (min_elevation_deg, max_elevation_deg):
        return None  # refused elsewhere (no band left), or used as asked
    asked = " ".join(
        f"--{name}-elevation-deg {value:g}"
        for name, value, typed, default in (
            ("min", min_elevation_deg, min_given, 0.0),
            ("max", max_elevation_deg, max_given, 90.0),
        )
        if typed or value != default
    )
    cone = f"{arm.keep_out_half_angle_deg:g}° keep-out cone around the camera"
    written = arm.configured_max_elevation_deg
    if written is not None and written > top:
        # the config's own limit, said as written: "its elevation limits 0°..75°" of a config
        # saying 90° read as if the config had been misread
        why = (
            f"its elevation joint may turn to {written:g}° as configured "
            f"([arm.dynamixel.elevation] max_deg), but above {top:g}° the lamp would be "
            f"inside the {cone}"
        )
    else:
        why = (
            f"its elevation limits {arm.min_elevation_deg:g}°..{arm.max_elevation_deg:g}° and "
            f"the {cone}"
        )
    return (
        f"{asked}: the arm reaches elevations {arm.min_elevation_deg:g}°..{top:g}° ({why}), "
        f"so the lights are spread over {lo:g}°..{hi:g}° only"
    )


def order_nearest_neighbour(
    directions: NDArray[np.float64], start: NDArray[np.float64]
) -> NDArray[np.intp]:
    """Greedy nearest-neighbour tour by angle, from ``start``: short moves for an arm."""
    remaining = list(range(len(directions)))
    order = []
    here = np.asarray(start, dtype=np.float64)
    while remaining:
        ang = angle_between_deg(directions[remaining], here)
        k = remaining.pop(int(np.argmin(ang)))
        order.append(k)
        here = directions[k]
    return np.asarray(order, dtype=np.intp)


#: Orders an arm's stops: (directions (n, 3), start direction) -> visiting order.
ArmOrder = Callable[[NDArray[np.float64], NDArray[np.float64]], Sequence[int]]


def plan_uniform(
    geometry: DomeGeometry | ArmGeometry,
    n: int,
    min_elevation_deg: float = 0.0,
    arm_order: ArmOrder | None = None,
    max_elevation_deg: float = 90.0,
) -> LightSchedule:
    """A homogeneous schedule of ``n`` lights between the elevation floor and ceiling, ordered
    for the rig.

    Dome steps go in LED order. Arm steps go in ``arm_order`` (the move-time-optimal order of
    :mod:`rti_rig.planner.arm_order` when the arm's servos are known), else nearest neighbour by
    angle.
    """
    provenance = {
        "n": n,
        "min_elevation_deg": min_elevation_deg,
        "max_elevation_deg": max_elevation_deg,
    }
    if isinstance(geometry, DomeGeometry):
        leds = select_uniform_leds(
            geometry, n, min_elevation_deg, max_elevation_deg=max_elevation_deg
        )
        return LightSchedule.from_directions(
            geometry.directions[leds],
            leds=[int(i) for i in leds],
            labels=[geometry.names[i] for i in leds],
            method="uniform",
            provenance=provenance,
        )
    dirs = arm_below(geometry, max_elevation_deg).homogeneous(n, min_elevation_deg)
    start = geometry.park_direction
    order = (arm_order or order_nearest_neighbour)(dirs, start)
    order = np.asarray(order, dtype=np.intp)
    return LightSchedule.from_directions(dirs[order], method="uniform", provenance=provenance)
