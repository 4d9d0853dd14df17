"""Use case: self-test a rig's lights before a session (``rti-rig check``).

A dome lights each LED in turn and reports what answered; an arm visits poses spanning its band,
checking where it really got to, flashes its lamp at each and parks (if its config says so).
The rig is closed — lights off, arm stopped — whatever happens.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.core.errors import RtiRigError
from rti_rig.core.rig_geometry import ArmGeometry
from rti_rig.runtime.arm_check import arm_self_test
from rti_rig.runtime.dome_policy import self_test
from rti_rig.runtime.lighting import ArmLighting, DomeLighting


@dataclass(frozen=True)
class CheckRequest:
    rig_config: Path
    #: LED drive level for a dome's walk, in (0, 1].
    intensity: float = 0.2


def check_rig(req: CheckRequest) -> Any:
    """The self-test report (``.lines()``, ``.ok``) of the rig ``req.rig_config`` describes."""
    if not 0.0 < req.intensity <= 1.0:
        raise RtiRigError(
            f"--intensity {req.intensity:g}: give the LED drive level as a fraction in (0, 1]"
        )
    loaded = load_rig_config(req.rig_config)
    if loaded.config.dome is not None and loaded.config.dome.flash_sync is not None:
        from rti_rig.app.flash_sync import flash_sync_check

        return flash_sync_check(loaded)
    with build_rig(loaded) as rig:
        if isinstance(rig.lighting, DomeLighting):
            return self_test(rig.lighting.source, rig.clock, intensity=req.intensity)
        if isinstance(rig.lighting, ArmLighting) and isinstance(rig.geometry, ArmGeometry):
            return arm_self_test(
                rig.lighting.carrier,
                rig.geometry,
                rig.clock,
                park=rig.lighting.park_after_session,
            )
        raise RtiRigError(f"{req.rig_config}: no self-test for this kind of lighting")
