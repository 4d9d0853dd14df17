"""A camera-triggered dome on hardware: what the composition root builds and what it refuses."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.app.flash_sync import SlipGuard
from rti_rig.app.usecases.safe_state import lights_state
from rti_rig.core.errors import ConfigError
from rti_rig.runtime.flash_sync import CameraTriggeredLighting

SHIPPED = (CONFIGS / "emulated_cceh_rti.toml").read_text(encoding="utf-8")


def hardware_config(tmp_path: Path, trigger: str = "none") -> Path:
    text = SHIPPED.replace('backend = "emulated"', 'backend = "hardware"')
    text += (
        f'\n[camera.device]\nkind = "folder_watch"\nfolder = "{tmp_path / "watch"}"\n'
        f'trigger = "{trigger}"\n'
    )
    (tmp_path / "watch").mkdir(exist_ok=True)
    path = tmp_path / "rig.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_hardware_rig_shoots_with_its_camera_and_commands_no_light(tmp_path: Path) -> None:
    with build_rig(load_rig_config(hardware_config(tmp_path))) as rig:
        assert isinstance(rig.lighting, CameraTriggeredLighting)
        assert isinstance(rig.capture_check, SlipGuard)
        assert "simulated" not in rig.camera.name
        state = lights_state(rig)
        assert "no all-off could be sent" in state and "4 s after the last flash" in state
        assert "not confirmed" in state


def test_a_dome_shutter_release_is_refused_without_a_dome_link(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"camera\.device\.trigger"):
        load_rig_config(hardware_config(tmp_path, trigger="dome_shutter"))


def test_more_leds_in_the_order_than_the_firmware_fires_is_refused(tmp_path: Path) -> None:
    text = SHIPPED.replace(
        "{ elevation_deg = 10.0, count = 16,", "{ elevation_deg = 10.0, count = 17,"
    )
    path = tmp_path / "rig.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(
        ConfigError, match="61 LEDs in the order, but the cceh-rti firmware fires 60"
    ):
        build_rig(load_rig_config(path))


def test_a_planned_exposure_past_the_firmware_timeout_is_refused_before_anything_moves() -> None:
    """The firmware's off-timeout bounds each exposure (not a host lit-time limit, which
    ``lit_limit_s`` stays None for: the host lights nothing, see its docstring): a step whose
    exposure the firmware would cut short is refused by the schedule's check, nothing shot."""
    from rti_rig.core.errors import ScheduleError
    from rti_rig.core.schedule import LightSchedule, LightStep
    from rti_rig.runtime.controller import validate_schedule

    with build_rig(load_rig_config(CONFIGS / "emulated_cceh_rti.toml")) as rig:
        lighting = rig.lighting
        assert isinstance(lighting, CameraTriggeredLighting)
        assert lighting.lit_limit_s() is None
        d = rig.geometry.directions
        steps = [
            LightStep(tuple(float(x) for x in d[i]), led=i, exposure_s=e)  # type: ignore[arg-type]
            for i, e in ((0, 4.0), (1, 4.5))
        ]
        with pytest.raises(ScheduleError) as refused:
            validate_schedule(rig, LightSchedule(steps))
        said = str(refused.value)
        assert "nothing has moved" in said and "1 problem(s)" in said, said
        assert "step 2" in said and "exposure 4.5 s" in said, said
        assert "switches its LED off 4 s after the flash pulse" in said, said
        assert rig.camera.exposures == 0  # type: ignore[attr-defined]
