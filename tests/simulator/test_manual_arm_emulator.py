"""The arm emulator's manual tool serves servos a real arm's check accepts.

``python -m rti_rig.simulator.dynamixel_emulator`` served two XL430s at 2048 ticks each. On the
shipped arm's geometry (elevation zero at 1024 ticks) that is 90° elevation, inside the 15°
keep-out cone, so ``rti-rig check`` on a copy of ``simulated_arm.toml`` pointed at its port was
refused at once: "the arm is not in a safe pose (elevation position 2048 ticks = 90.000 deg
enters the keep-out cone (max 75.000 deg)); move it by hand" — which no one can do to an
emulator. It now serves a rig config's servos at that config's park pose.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.clock import SystemClock, VirtualClock
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.drivers.dynamixel.kinematics import ArmKinematics
from rti_rig.simulator.dynamixel_emulator import arm_settings_of, served_arm

pytestmark = pytest.mark.pty


def test_the_default_servos_connect_to_the_shipped_arm_outside_its_keep_out() -> None:
    settings, where = arm_settings_of(None)
    assert where.endswith("simulated_arm.toml")
    clock = VirtualClock()
    with served_arm(settings, clock) as (server, emulator):
        pos = emulator.joint_positions()
        kin = ArmKinematics(settings)
        az, el = pos[settings.azimuth.servo_id], pos[settings.elevation.servo_id]
        assert kin.ticks_reason(az, el, "position") is None
        arm = DynamixelArm(settings, server.port_handler(), clock)
        arm.connect()  # refused with SafetyViolation at 2048/2048 ticks
        arm.close()


def test_a_config_other_than_the_shipped_one_is_served_at_its_own_park() -> None:
    settings, _ = arm_settings_of(str(CONFIGS / "simulated_arm.toml"))
    moved = settings.model_copy(update={"park_azimuth_deg": 30.0, "park_elevation_deg": 40.0})
    with served_arm(moved, VirtualClock()) as (_, emulator):
        pos = emulator.joint_positions()
        assert (pos[1], pos[2]) == ArmKinematics(moved).ticks_of_pose(30.0, 40.0)


def test_a_file_without_an_arm_is_named() -> None:
    with pytest.raises(ValueError, match=r"emulated_minirti\.toml: no \[arm\.dynamixel\] table"):
        arm_settings_of(str(CONFIGS / "emulated_minirti.toml"))


def test_the_tool_says_where_the_servos_rest_and_what_to_set() -> None:
    out = subprocess.run(
        [sys.executable, "-m", "rti_rig.simulator.dynamixel_emulator", "--seconds", "0"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert "resting at the park pose of" in out.stdout and "elevation 10°" in out.stdout
    assert 'backend = "hardware", [arm.dynamixel] port = "' in out.stdout


@pytest.mark.parametrize(
    "module",
    ["simulator.dynamixel_pty", "rti_rig.simulator.dynamixel_pty"],
    ids=["repo", "installed"],
)
def test_the_pty_link_module_names_the_tool_that_serves_servos(module: str) -> None:
    """``python -m simulator.dynamixel_pty --help`` printed nothing: the module is the pty link,
    and the tool that serves servos on a pty is another. Its help now names that tool, and so
    does a run without --help (which serves nothing, so it does not exit 0); the named tool
    exists and answers --help."""
    repo = CONFIGS.parent

    def run(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [sys.executable, "-m", *args], capture_output=True, text=True, timeout=120, cwd=repo
        )

    tool = "python -m rti_rig.simulator.dynamixel_emulator"
    helped = run(module, "--help")
    assert helped.returncode == 0, helped.stderr
    assert helped.stdout.startswith(f"usage: {tool} "), helped.stdout
    bare = run(module, "--config", "rig.toml")
    assert bare.returncode == 2, bare
    assert f"serves nothing by itself: run {tool}" in bare.stderr, bare.stderr
    named = run(tool.removeprefix("python -m ").strip(), "--help")
    assert named.returncode == 0 and "Serve a rig config's arm servos" in named.stdout, named


def test_a_hardware_arm_is_named_with_its_port(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A real arm's check said "ABORTED: arm during 'ping': servo 3: no servo with id 3
    answers at 57600 baud …": no port, on a bench where a dome's and an arm's adapters sit side
    by side. The arm is now "arm on PORT" in every line, as a hardware dome is."""
    import dynamixel_sdk

    settings, where = arm_settings_of(None)
    with served_arm(settings, SystemClock()) as (server, _):
        port = server.device_path
        # the SDK's port on the pty, with the server's causal reply timeouts (no wall-time
        # window for a loaded machine to miss)
        monkeypatch.setattr(dynamixel_sdk, "PortHandler", lambda _path: server.port_handler())
        text = Path(where).read_text()
        text = text.replace('backend = "emulated"', 'backend = "hardware"')
        text = text.replace('transport = "pty"', "")
        text = re.sub(r'port = "emulated".*', f'port = "{port}"', text)
        text = text.replace("servo_id = 2", "servo_id = 3")  # the elevation servo's id is wrong
        (tmp_path / "tether").mkdir()
        text += f'\n[camera.device]\nkind = "folder_watch"\nfolder = "{tmp_path / "tether"}"\n'
        cfg = tmp_path / "arm.toml"
        cfg.write_text(text)
        r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert f"arm on {port}: no pose visited" in said, said
    assert f"ABORTED: arm on {port} during 'ping': servo 3: no servo with id 3" in said, said
