"""Turning a plan read from an `.lp` file into a schedule for a particular rig.

A plan's directions must be runnable as they are: on a dome each must be one of its LEDs (within
a tolerance, since `.lp` files carry six decimals), used once; on an arm each must be reachable.
Errors name the plan file and line, because that is what the user has to fix.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rti_rig.core.errors import ScheduleError
from rti_rig.core.lp_format import LpEntry
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.core.schedule import LightSchedule
from rti_rig.core.shell_words import shown_path

#: Plan directions farther than this from every LED are not that dome's LEDs.
SNAP_TOLERANCE_DEG = 1.0


def schedule_from_lp(
    entries: Sequence[LpEntry],
    geometry: DomeGeometry | ArmGeometry,
    source: str,
    tolerance_deg: float = SNAP_TOLERANCE_DEG,
    replan: str = "",
) -> LightSchedule:
    """The schedule an `.lp` plan describes on this rig, in the plan's order.

    ``replan``: the command that plans for this rig, named where a light is not its own (the
    CLI's, with the rig config's path; "replan with --rig" alone had left the user to spell
    it out)."""
    how = f": {replan}" if replan else " with --rig"
    dirs = np.array([e.direction for e in entries], dtype=np.float64)
    prov = {"plan_file": source}  # as on disk, for the manifest
    # as the user pastes it: a name that is not UTF-8 (or unprintable here) as its bytes
    named = shown_path(source)
    if isinstance(geometry, ArmGeometry):
        for i, (e, d) in enumerate(zip(entries, dirs, strict=True)):
            reason = geometry.unreachable_reason(d)
            if reason:  # what to do, as a dome's refusal says it (it had said only why)
                raise ScheduleError(
                    f"{named}, light {i + 1} ({e.name}): {reason}; the plan was made for "
                    f"another rig — replan for this arm{how}"
                )
        return LightSchedule.from_directions(
            dirs, labels=[e.name for e in entries], method="plan", provenance=prov
        )
    leds: list[int] = []
    used: dict[int, int] = {}
    for i, (e, d) in enumerate(zip(entries, dirs, strict=True)):
        led, off = geometry.nearest_led(d)
        if off > tolerance_deg:
            raise ScheduleError(
                f"{named}, light {i + 1} ({e.name}): no LED of this dome within "
                f"{tolerance_deg:g}° (nearest is {geometry.led_said(led)}, {off:.2f}° away); "
                f"the plan was made for another dome — replan for this one{how}"
            )
        if led in used:
            raise ScheduleError(
                f"{named}, light {i + 1} ({e.name}): {geometry.led_said(led)} is already used by "
                f"light {used[led] + 1}; a plan fires each LED once"
            )
        used[led] = i
        leds.append(led)
    return LightSchedule.from_directions(
        geometry.directions[leds],
        leds=leds,
        labels=[e.name for e in entries],
        method="plan",
        provenance=prov,
    )
