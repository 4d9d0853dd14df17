"""Fixing a session's exposure before it starts, from a short test series at its brightest light.

One exposure serves the whole session (RTI fitting assumes it): it must keep the brightest
image under the saturation limit. The brightest planned light is taken to be the one nearest
the camera axis (most irradiance on a roughly level object); the metering itself — test shots,
prediction, verification — is the camera driver layer's ``meter`` function, injected here so that
this policy stays free of drivers. The chosen exposure is written into every step of the
schedule, and the evidence into its provenance, which the manifest records.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from rti_rig.core.errors import DeviceError
from rti_rig.core.schedule import LightSchedule
from rti_rig.runtime.controller import validate_schedule
from rti_rig.runtime.lighting import attempt_all
from rti_rig.runtime.rig import Rig

#: ``meter(camera, start_exposure_s) -> choice`` where ``choice.exposure_s`` is the pick and
#: ``choice.to_manifest()`` the evidence.
Meter = Callable[[Any, float], Any]


def brightest_step(schedule: LightSchedule) -> int:
    """Index of the planned light nearest the camera axis."""
    return int(np.argmax(schedule.directions[:, 2]))


def fix_session_exposure(rig: Rig, schedule: LightSchedule, meter: Meter) -> LightSchedule:
    """Meter at the brightest planned light and return the schedule with that exposure fixed.

    The schedule is validated first (nothing moves for a schedule the rig cannot run), the
    light is always switched off again, and devices are closed so that the session starts from
    a clean connect.
    """
    validate_schedule(rig, schedule)
    i = brightest_step(schedule)

    def teardown() -> list[str]:
        # every step of the teardown runs, whatever one device does; what failed is said
        return rig.lighting.safe() + attempt_all(
            [("camera close", rig.camera.close), ("lights close", rig.lighting.close)]
        )

    try:
        rig.lighting.connect()
        rig.camera.connect()
        rig.lighting.set(schedule.steps[i])
        rig.clock.sleep(rig.timing.settle_s)
        choice = meter(rig.camera, rig.camera_config.exposure_s)
    except BaseException as exc:
        # a Ctrl-C or an error while metering: what the teardown could not do travels with it
        # (it had been dropped, and the user told an all-off was sent)
        exc.teardown_failures = teardown()  # type: ignore[attr-defined]
        raise
    failures = teardown()
    if failures:
        raise DeviceError(
            rig.name,
            "metering could not make the rig safe (" + "; ".join(failures) + "): check the "
            "lights before anything else",
            "meter",
        )
    steps = tuple(replace(s, exposure_s=float(choice.exposure_s)) for s in schedule.steps)
    evidence = {**choice.to_manifest(), "metered_at_step": i + 1}
    fixed = replace(schedule, steps=steps, provenance={**schedule.provenance, "exposure": evidence})
    validate_schedule(rig, fixed)
    return fixed
