"""The preview shot's light: one light at the paper's elevation, the rig's own.

The paper plans from "an acquisition from 45 to 60 degrees of elevation": high enough that
little of the object is in cast shadow, low enough that its relief shades. The planner also
needs to know that light exactly, so the preview is shot by the rig (a dome's LED, an arm's
reachable direction) and the direction that fired is recorded with the image.
"""

from __future__ import annotations

import numpy as np

from rti_rig.core.errors import ScheduleError
from rti_rig.core.fit_minimums import NORMAL_MIN_LIGHTS
from rti_rig.core.geometry import angle_between_deg, az_el_from_direction, direction_from_az_el
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry, in_band
from rti_rig.core.schedule import LightSchedule
from rti_rig.planner.from_lp import SNAP_TOLERANCE_DEG
from rti_rig.planner.uniform import arm_below

#: Default preview light (degrees): top left of the image, as objects are conventionally lit,
#: at the middle of the paper's 45–60° band.
PREVIEW_AZ_EL_DEG = (135.0, 50.0)

#: The paper's preview elevations (degrees): a dome's default preview LED is taken from this
#: band when it has one there.
PAPER_BAND_DEG = (45.0, 60.0)

#: Elevations (degrees) outside which a preview's shading says little (grazing: long cast
#: shadows; near the camera axis: no shading, and highlights).
PREVIEW_BAND_DEG = (30.0, 70.0)


#: Every elevation: no ``--min/--max-elevation-deg`` given.
FULL_BAND_DEG = (0.0, 90.0)


def _band_option(el: float, band: tuple[float, float]) -> str:
    """Which side of ``band`` ``el`` lies on, naming the option (``above --max-elevation-deg
    45``): the user fixes what the message names."""
    lo, hi = band
    return f"above --max-elevation-deg {hi:g}" if el > hi else f"below --min-elevation-deg {lo:g}"


def refuse_unplannable_band(geometry: object, band: tuple[float, float]) -> None:
    """Refuse a preview whose band holds a dome LED or two but fewer than a plan needs.

    Why: a preview is the input of a plan in its band. On a dome with 2 LEDs at 85°, ``rti-rig
    preview DOME --min-elevation-deg 80`` shot one of them and printed "Plan from it: rti-rig
    plan ... --lights 3 --min-elevation-deg 80", refused when pasted ("asked for 3 lights but
    the dome has only 2 LEDs"). A band with no LED is refused by :func:`preview_schedule`,
    naming the same way out; an arm's band holds any number of lights.
    """
    if not isinstance(geometry, DomeGeometry):
        return
    lo, hi = band
    held = int(in_band(az_el_from_direction(geometry.directions)[1], lo, hi).sum())
    leds = f"{held} LED{'s' if held > 1 else ''}"
    if 0 < held < NORMAL_MIN_LIGHTS and tuple(band) == FULL_BAND_DEG:
        raise ScheduleError(
            f"the dome has only {leds}, and a plan needs at least {NORMAL_MIN_LIGHTS} (a surface "
            "normal's 3 unknowns): no plan can be made for it from a preview"
        )
    if 0 < held < NORMAL_MIN_LIGHTS:
        raise ScheduleError(
            f"the dome has only {leds} between {lo:g}° and {hi:g}° elevation, and a plan in "
            f"that band needs at least {NORMAL_MIN_LIGHTS} (a surface normal's 3 unknowns); "
            "widen --min-elevation-deg / --max-elevation-deg"
        )


def preview_schedule(
    geometry: DomeGeometry | ArmGeometry,
    az_el_deg: tuple[float, float] | None = None,
    band: tuple[float, float] = FULL_BAND_DEG,
    shot_as: str = "",
) -> tuple[LightSchedule, list[str]]:
    """A one-step schedule lighting from ``az_el_deg`` on this rig, and notes for the user.

    A dome uses its LED nearest the wanted direction (noted when it is farther than an `.lp`'s
    rounding); by default (``None``: :data:`PREVIEW_AZ_EL_DEG`) the nearest among its LEDs in
    the paper's band, if it has any there. An arm goes there, or the limit it would break is
    the error; by default, the nearest pose it reaches within the band (noted), since the
    default is the rig's to choose.

    ``band`` (``--min/--max-elevation-deg``, as ``plan`` and ``run`` take them): the preview
    keeps to it, so that a user who plans a gilded object under a 45° ceiling is not handed a
    preview already shot at 50°. The default light's elevation is clamped into the band (a dome
    then takes its nearest LED in the band, preferring the paper's band only where the two
    overlap by more than an edge); a light asked for outside the band is refused, naming the
    option; a dome fires only an LED in the band, the nearest to the light asked for.

    A note names a dome's LED by its number (as ``check`` and the dome's errors count them,
    from 0) and where it lights from, and ``shot_as``, the file the preview writes under it,
    where given. Why not by its name in the dome's ``.lp``: that is the image name of another
    acquisition ("led_036.jpg"), and the preview's image was ``image_001.jpg``: a user looked
    for a file the preview never wrote.
    """
    lo_band, hi_band = band
    if isinstance(geometry, ArmGeometry):
        # a ceiling at or below the arm's lowest elevation is refused naming the option, as
        # run's and plan's layouts refuse it: the preview had blamed the light ("give a
        # --light AZ,EL the arm can reach"), and any light the arm can reach is above the band
        arm_below(geometry, hi_band)
    if az_el_deg is not None:
        az, el = az_el_deg
    else:  # the default direction, its elevation clamped into the band
        az, el = PREVIEW_AZ_EL_DEG[0], min(max(PREVIEW_AZ_EL_DEG[1], lo_band), hi_band)
    if not 0.0 <= el <= 90.0:
        raise ScheduleError(f"preview light elevation {el:g}° is outside 0..90°")
    if not in_band(el, lo_band, hi_band):  # only a light asked for can be
        raise ScheduleError(
            f"--light {az:g},{el:g}: its elevation {el:g}° is {_band_option(el, band)} (the "
            f"band {lo_band:g}–{hi_band:g}°): give a light within the band, or widen it"
        )
    wanted = direction_from_az_el(az, el)
    notes: list[str] = []
    prov: dict[str, object] = {"purpose": "preview", "wanted_az_el_deg": [float(az), float(el)]}
    if tuple(band) != FULL_BAND_DEG:
        prov["elevation_band_deg"] = [float(lo_band), float(hi_band)]
    if isinstance(geometry, DomeGeometry):
        _, els = az_el_from_direction(geometry.directions)
        allowed = np.flatnonzero(in_band(els, lo_band, hi_band))
        if allowed.size == 0:
            raise ScheduleError(
                f"the dome has no LED between {lo_band:g}° and {hi_band:g}° elevation; widen "
                "--min-elevation-deg / --max-elevation-deg"
            )
        ang = angle_between_deg(geometry.directions[allowed], wanted)
        led, off = int(allowed[np.argmin(ang)]), float(ang.min())
        which = "the nearest" if allowed.size == len(els) else "the nearest in the band"
        # by default the paper's band where it is part of the band asked for (not merely its
        # edge: under a 45° ceiling an LED at 45° across the dome would beat one at 40° beside
        # the default direction)
        lo, hi = max(PAPER_BAND_DEG[0], lo_band), min(PAPER_BAND_DEG[1], hi_band)
        if az_el_deg is None and lo < hi:
            paper = allowed[(els[allowed] >= lo) & (els[allowed] <= hi)]
            if paper.size:
                ang = angle_between_deg(geometry.directions[paper], wanted)
                led, off = int(paper[np.argmin(ang)]), float(ang.min())
                which = "the nearest in the paper's {:g}–{:g}° band".format(*PAPER_BAND_DEG)
                if (lo, hi) != tuple(PAPER_BAND_DEG):  # only the part inside the band asked for
                    which = f"the nearest at {lo:g}–{hi:g}° (the paper's band within yours)"
        d = geometry.directions[led]
        if off > SNAP_TOLERANCE_DEG:
            got_az, got_el = (float(v) for v in az_el_from_direction(d))
            shot = f"; the preview's {shot_as} is shot under it" if shot_as else ""
            notes.append(
                f"no LED at az {az:g}°, el {el:g}°: {which}, LED {led} "
                f"(az {got_az:.1f}°, el {got_el:.1f}°), is {off:.1f}° away{shot}"
            )
        schedule = LightSchedule.from_directions(
            [d], leds=[led], labels=[geometry.names[led]], method="preview", provenance=prov
        )
    else:
        reason = geometry.unreachable_reason(wanted)
        nearest = _arm_default_nearest(geometry, az, el, band) if az_el_deg is None else None
        if reason and nearest is not None:
            # the default is the rig's to choose, as a dome's nearest LED is: it had been
            # refused on every arm whose azimuth stops short of 135° ("give --light AZ,EL the
            # arm can reach"), a bare `rti-rig preview RIG.toml` failing on a shipped-style arm
            near_az, near_el = nearest
            shot = f"; the preview's {shot_as} is shot under it" if shot_as else ""
            notes.append(
                f"the default preview light (az {az:g}°, el {el:g}°) is beyond the arm's reach "
                f"({reason}): the nearest it reaches, az {near_az:g}°, el {near_el:g}°, is used"
                f"{shot} (--light AZ,EL chooses another)"
            )
            az, el, reason = near_az, near_el, None
            wanted = direction_from_az_el(az, el)
        if reason:
            # named as the user gave it, with what to do: the bare limit had left them to
            # guess that --light was the thing to change
            if az_el_deg is not None:
                asked, todo = f"--light {az:g},{el:g}", "give a --light AZ,EL the arm can reach"
            else:
                asked = f"the default preview light (az {az:g}°, el {el:g}°)"
                todo = (
                    "give --light AZ,EL the arm can reach, or an elevation band "
                    "(--min-elevation-deg / --max-elevation-deg) within its reach"
                )
            raise ScheduleError(f"{asked}: the arm cannot go there ({reason}); {todo}")
        schedule = LightSchedule.from_directions([wanted], method="preview", provenance=prov)
    _, got = az_el_from_direction(schedule.steps[0].direction)
    lo, hi = PREVIEW_BAND_DEG
    # with the tolerance of the band checks above: an arm sent to 30° reads back 29.99...°
    # from its direction, and had been told "at 30° elevation: outside 30–70°"
    if not lo - 1e-9 <= float(got) <= hi + 1e-9:
        notes.append(
            f"the preview light is at {float(got):.0f}° elevation: outside {lo:g}–{hi:g}°, "
            "its shading says little about the relief (the paper shoots at 45–60°)"
        )
    return schedule, notes


def _arm_default_nearest(
    geometry: ArmGeometry, az: float, el: float, band: tuple[float, float]
) -> tuple[float, float] | None:
    """The pose nearest the default preview light (``az``, ``el``) that ``geometry`` reaches
    within ``band``: the azimuth moved onto its nearer joint limit (measured round the circle),
    the elevation into the reachable part of the band; None when no elevation of the band is
    reachable (then the default's refusal names the band, as before)."""
    lo = max(band[0], geometry.min_elevation_deg)
    hi = min(band[1], geometry.max_elevation_deg, 90.0 - geometry.keep_out_half_angle_deg)
    if lo > hi:
        return None
    a = (az + 180.0) % 360.0 - 180.0
    lo_az, hi_az = geometry.min_azimuth_deg, geometry.max_azimuth_deg
    if not lo_az <= a <= hi_az:
        a = min((lo_az, hi_az), key=lambda limit: abs((a - limit + 180.0) % 360.0 - 180.0))
    near = (a, min(max(el, lo), hi))
    return None if geometry.unreachable_reason(direction_from_az_el(*near)) else near
