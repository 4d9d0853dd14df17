"""Dry runs through the real dome driver and real pyserial, against the firmware emulator."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import CONFIGS, write_config
from typer.testing import CliRunner

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.core.errors import ConfigError, DeviceError
from rti_rig.core.lp_format import read_lp
from rti_rig.runtime.controller import run_session
from rti_rig.runtime.session import SessionFolder
from rti_rig.testing.verify import wrong_light_steps

runner = CliRunner()


def small_emulated(tmp_path: Path, extra: str = "") -> Path:
    text = (CONFIGS / "emulated_dome.toml").read_text()
    text = text.replace("width = 256", "width = 48").replace("height = 256", "height = 48")
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    return write_config(tmp_path, text + extra)


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


@pytest.mark.e2e
@pytest.mark.pty
def test_cli_dry_run_through_the_emulated_dome(tmp_path: Path) -> None:
    cfg = small_emulated(tmp_path)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "10"])
    assert r.exit_code == 0, r.output
    assert "(dry run)" in said(r)
    entries = read_lp(out / "lights.lp")
    assert len(entries) == 10
    assert wrong_light_steps(cfg, out) == []
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["rig"]["backend"] == "emulated"


@pytest.mark.e2e
@pytest.mark.pty
def test_a_dry_run_whose_first_handshake_reply_is_lost_completes(tmp_path: Path) -> None:
    """The emulated board drops its reply to the very first handshake (after its boot banner):
    the handshake is sent again and the run completes. It had failed at its start with "no
    handshake with the dome … check the port, the baud rate and the protocol profile"."""
    cfg = small_emulated(
        tmp_path, '\n[emulator]\nfaults = [{at_command = 1, kind = "drop_reply"}]\n'
    )
    # a reply timeout no CPU load exhausts on the pty (the dropped reply costs it once)
    cfg.write_text(cfg.read_text().replace("reply_timeout_s = 0.5", "reply_timeout_s = 2.0"))
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
    assert r.exit_code == 0, r.output
    assert "no handshake" not in said(r)
    assert len(read_lp(out / "lights.lp")) == 4
    assert wrong_light_steps(cfg, out) == []


@pytest.mark.e2e
@pytest.mark.pty
def test_a_dry_run_whose_board_drops_off_the_usb_at_the_handshake_completes(
    tmp_path: Path,
) -> None:
    """The emulated board sends its banner, then its pty vanishes as the first handshake
    arrives (a USB drop; back 0.3 s later behind the same path): the port is reopened and the
    run completes. It had failed at its start with "no handshake with the dome … check the
    port, the baud rate and the protocol profile", through real pyserial's own errors."""
    cfg = small_emulated(
        tmp_path,
        '\n[emulator]\nfaults = [{at_command = 1, kind = "disconnect", delay_s = 0.3}]\n',
    )
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
    assert r.exit_code == 0, r.output
    assert "no handshake" not in said(r) and "port was lost" not in said(r)
    assert len(read_lp(out / "lights.lp")) == 4
    assert wrong_light_steps(cfg, out) == []


@pytest.mark.e2e
@pytest.mark.pty
def test_a_check_whose_board_drops_off_for_good_at_the_handshake_names_the_usb_link(
    tmp_path: Path,
) -> None:
    """Gone for good: the check fails saying the port was lost during the handshake and to
    check the USB cable, hub and power, not the port, baud rate and profile it had said."""
    cfg = small_emulated(
        tmp_path,
        '\n[emulator]\nfaults = [{at_command = 1, kind = "disconnect", delay_s = 60.0}]\n',
    )
    cfg.write_text(cfg.read_text().replace("reconnect_attempts = 3", "reconnect_attempts = 1"))
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 1, r.output
    text = said(r)
    assert "port was lost during the handshake" in text
    assert "check the USB cable, the USB hub and the board's power supply" in text
    assert "check the port, the baud rate" not in text


@pytest.mark.pty
def test_firmware_really_lit_each_recorded_led(tmp_path: Path) -> None:
    loaded = load_rig_config(small_emulated(tmp_path))
    from rti_rig.planner.uniform import plan_uniform

    with build_rig(loaded) as rig:
        fw = rig.emulator  # type: ignore[attr-defined]
        schedule = plan_uniform(rig.geometry, 6)
        lit_during_capture: list[int | None] = []
        real_capture = rig.camera.capture

        def capture(exposure_s: float):  # type: ignore[no-untyped-def]
            lit = fw.lit
            lit_during_capture.append(None if lit is None else lit[0])
            return real_capture(exposure_s)

        rig.camera.capture = capture  # type: ignore[method-assign]
        result = run_session(rig, schedule, SessionFolder.create(tmp_path / "s", 6))
        assert [r.led for r in result.records] == lit_during_capture
        assert fw.lit is None  # all off after the session


@pytest.mark.e2e
@pytest.mark.pty
def test_check_passes_and_names_a_dead_led(tmp_path: Path) -> None:
    r = runner.invoke(app, ["check", str(small_emulated(tmp_path))])
    assert r.exit_code == 0, r.output
    assert "RESULT: PASS" in r.output
    dead = small_emulated(tmp_path, "\n[emulator]\ndead_leds = [5]\n")
    r = runner.invoke(app, ["check", str(dead)])
    assert r.exit_code == 1, r.output
    assert "LED 5" in said(r)


@pytest.mark.pty
def test_dead_led_stops_the_session_naming_it(tmp_path: Path) -> None:
    cfg = small_emulated(tmp_path, "\n[emulator]\ndead_leds = [3]\n")
    loaded = load_rig_config(cfg)
    from rti_rig.core.schedule import LightSchedule

    with build_rig(loaded) as rig:
        dirs = rig.geometry.directions
        schedule = LightSchedule.from_directions(dirs[:5], leds=[0, 1, 2, 3, 4])
        out = tmp_path / "s"
        with pytest.raises(DeviceError, match="LED 3"):
            run_session(rig, schedule, SessionFolder.create(out, 5))
        assert rig.emulator.lit is None  # type: ignore[attr-defined]
    assert len(read_lp(out / "lights.lp")) == 3


@pytest.mark.parametrize(
    ("edit", "key", "fragment"),
    [
        (("baudrate = 115200", 'baudrate = "fast"'), "dome.serial.baudrate", "integer"),
        (('profile = "default"', 'profile = "morse"'), "dome.serial.profile", "default"),
        (("[dome.serial]", "[dome.serail]"), "dome.serail", "unknown key"),
    ],
)
def test_serial_config_errors_name_the_key(
    tmp_path: Path, edit: tuple[str, str], key: str, fragment: str
) -> None:
    text = small_emulated(tmp_path).read_text().replace(*edit)
    with pytest.raises(ConfigError) as info:
        load_rig_config(write_config(tmp_path, text, "bad.toml"))
    assert info.value.key == key
    assert fragment in info.value.message


def test_hardware_configs_validate_without_hardware() -> None:
    loaded = load_rig_config(CONFIGS / "example_dome_48.toml")
    assert loaded.config.backend == "hardware"
    assert loaded.config.dome is not None and loaded.config.dome.serial is not None


def test_hardware_needs_a_camera_device(tmp_path: Path) -> None:
    text = (CONFIGS / "example_dome_48.toml").read_text()
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    # drop the [camera.device] tables (and their decode sub-table), keep [timing]
    no_cam = text[: text.index("[camera.device]")] + text[text.index("[timing]") :]
    with pytest.raises(ConfigError, match=r"needs a \[camera.device\] table"):
        load_rig_config(write_config(tmp_path, no_cam))
    bad_cam = text.replace('kind = "gphoto2"', 'kind = "gphoto2"\nshutter = 3')
    with pytest.raises(ConfigError) as info:
        load_rig_config(write_config(tmp_path, bad_cam, "b.toml"))
    assert info.value.key is not None and info.value.key.startswith("camera.device")
