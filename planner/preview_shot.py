"""The preview shot's light: one light at the paper's elevation, the rig's own.

The paper plans from "an acquisition from 45 to 60 degrees of elevation": high enough that
little of the object is in cast shadow, low enough that its relief shades. The planner also
needs to know that light exactly, so the preview is shot by the rig (a dome's LED, an arm's
reachable direction) and the direction that fired is recorded with the image.
"""

from __future__ import annotations

import numpy as np

from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import angle_between_deg, az_el_from_direction, direction_from_az_el
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.core.schedule import LightSchedule
from rti_rig.planner.from_lp import SNAP_TOLERANCE_DEG

#: Default preview light (degrees): top left of the image, as objects are conventionally lit,
#: at the middle of the paper's 45–60° band.
PREVIEW_AZ_EL_DEG = (135.0, 50.0)

#: The paper's preview elevations (degrees): a dome's default preview LED is taken from this
#: band when it has one there.
PAPER_BAND_DEG = (45.0, 60.0)

#: Elevations (degrees) outside which a preview's shading says little (grazing: long cast
#: shadows; near the camera axis: no shading, and highlights).
PREVIEW_BAND_DEG = (30.0, 70.0)


def preview_schedule(
    geometry: DomeGeometry | ArmGeometry, az_el_deg: tuple[float, float] | None = None
) -> tuple[LightSchedule, list[str]]:
    """A one-step schedule lighting from ``az_el_deg`` on this rig, and notes for the user.

    A dome uses its LED nearest the wanted direction (noted when it is farther than an `.lp`'s
    rounding); by default (``None``: :data:`PREVIEW_AZ_EL_DEG`) the nearest among its LEDs in
    the paper's band, if it has any there. An arm goes there, or the limit it would break is
    the error.
    """
    az, el = az_el_deg if az_el_deg is not None else PREVIEW_AZ_EL_DEG
    if not 0.0 <= el <= 90.0:
        raise ScheduleError(f"preview light elevation {el:g}° is outside 0..90°")
    wanted = direction_from_az_el(az, el)
    notes: list[str] = []
    prov = {"purpose": "preview", "wanted_az_el_deg": [float(az), float(el)]}
    if isinstance(geometry, DomeGeometry):
        led, off = geometry.nearest_led(wanted)
        which = "the nearest"
        if az_el_deg is None:
            _, els = az_el_from_direction(geometry.directions)
            lo, hi = PAPER_BAND_DEG
            band = np.flatnonzero((els >= lo) & (els <= hi))
            if band.size:
                ang = angle_between_deg(geometry.directions[band], wanted)
                led, off = int(band[np.argmin(ang)]), float(ang.min())
                which = f"the nearest in the paper's {lo:g}–{hi:g}° band"
        d = geometry.directions[led]
        if off > SNAP_TOLERANCE_DEG:
            got_az, got_el = (float(v) for v in az_el_from_direction(d))
            notes.append(
                f"no LED at az {az:g}°, el {el:g}°: {which}, {geometry.names[led]} "
                f"(az {got_az:.1f}°, el {got_el:.1f}°), is {off:.1f}° away"
            )
        schedule = LightSchedule.from_directions(
            [d], leds=[led], labels=[geometry.names[led]], method="preview", provenance=prov
        )
    else:
        reason = geometry.unreachable_reason(wanted)
        if reason:
            raise ScheduleError(f"preview light az {az:g}°, el {el:g}°: {reason}")
        schedule = LightSchedule.from_directions([wanted], method="preview", provenance=prov)
    _, got = az_el_from_direction(schedule.steps[0].direction)
    lo, hi = PREVIEW_BAND_DEG
    if not lo <= float(got) <= hi:
        notes.append(
            f"the preview light is at {float(got):.0f}° elevation: outside {lo:g}–{hi:g}°, "
            "its shading says little about the relief (the paper shoots at 45–60°)"
        )
    return schedule, notes
