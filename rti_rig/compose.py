"""The composition root: turns a validated rig config into devices.

This is the one place in the core that imports ``simulator`` (and, as backends arrive,
``drivers``): the backend is chosen by the config's ``backend`` key, never by magic port names.
"""

from __future__ import annotations

from rti_rig.assembly import Rig
from rti_rig.clock import Clock, VirtualClock
from rti_rig.config import LoadedRig, rig_geometry
from rti_rig.errors import ConfigError
from rti_rig.lighting import ArmLighting, DomeLighting
from rti_rig.rig_geometry import ArmGeometry, DomeGeometry


def build_rig(loaded: LoadedRig, clock: Clock | None = None) -> Rig:
    """Build the rig a config describes. Simulated rigs get a virtual clock by default."""
    cfg = loaded.config
    if cfg.backend != "simulated":
        raise ConfigError(loaded.path, "backend", f"backend {cfg.backend!r} is not available")
    return _build_simulated(loaded, clock or VirtualClock())


def _build_simulated(loaded: LoadedRig, clock: Clock) -> Rig:
    from simulator.sim_camera import SimulatedCamera
    from simulator.sim_lights import LightState, SimulatedArm, SimulatedDome
    from simulator.sim_scene import lambert_radiance, relief_scene

    cfg = loaded.config
    if cfg.scene.name != "relief":
        raise ConfigError(
            loaded.path, "scene.name", f"unknown scene {cfg.scene.name!r}; available: 'relief'"
        )
    scene = relief_scene(cfg.camera.height, cfg.camera.width, cfg.scene.seed)
    state = LightState()

    def render(direction, intensity):  # type: ignore[no-untyped-def]
        if direction is None:
            return scene.albedo * 0.0
        return lambert_radiance(scene, direction, intensity)

    geometry = rig_geometry(loaded)
    if isinstance(geometry, DomeGeometry):
        lighting = DomeLighting(
            SimulatedDome(geometry, state, clock, cfg.timing.light_switch_s), geometry
        )
    else:
        assert isinstance(geometry, ArmGeometry) and cfg.arm is not None
        lighting = ArmLighting(
            SimulatedArm(
                geometry,
                state,
                clock,
                speed_deg_s=cfg.arm.speed_deg_s,
                acceleration_deg_s2=cfg.arm.acceleration_deg_s2,
                resolution_deg=cfg.arm.resolution_deg,
                switch_s=cfg.timing.light_switch_s,
            ),
            park_after_session=cfg.arm.park_after_session,
            park_on_emergency=cfg.arm.park_on_emergency_stop,
        )
    camera = SimulatedCamera(
        render,
        state,
        clock,
        reference_exposure_s=cfg.camera.exposure_s,
        readout_s=cfg.timing.readout_s,
        transfer_s=cfg.timing.transfer_s,
        noise=cfg.scene.noise,
        seed=cfg.scene.seed,
        raw=cfg.scene.raw,
    )
    return Rig(loaded=loaded, geometry=geometry, lighting=lighting, camera=camera, clock=clock)
