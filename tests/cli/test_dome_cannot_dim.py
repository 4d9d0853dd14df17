"""A dome whose link cannot dim an LED is never given, nor said to have, a light correction.

Found by an audit: `calibrate-lights` asked a codec chosen by elimination whether the dome could
dim, and every real firmware profile got a binary codec that "carries a level". So it wrote a
correction for the nab-rti-v1 sketch (whose only light command switches an LED fully on) and
told the user to install it; with it installed, `check` said PASS, `run` gave the images of no
correction, and `--auto-exposure` took the dome for evened out (metered at one light instead of
the planned six). Each profile now declares whether it can dim (docs/../dome-firmwares.md: no
described firmware's light command carries a brightness), and every reader asks that one fact.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, UnlimitedLighting, write_config
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.app.dome_factory import build_dome
from rti_rig.cli import app
from rti_rig.core.clock import VirtualClock
from rti_rig.core.errors import DeviceError
from rti_rig.drivers.led_dome.dome_profiles import described_profiles, no_dimming
from rti_rig.drivers.led_dome.driver import LedDomeDriver
from rti_rig.drivers.led_dome.factory import build_driver, protocol_for
from rti_rig.drivers.led_dome.profiles import make_codec
from rti_rig.drivers.led_dome.scripted import ScriptedDomeDriver
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.drivers.led_dome.transport import SerialTransport

runner = CliRunner()

#: From the firmwares' published behaviour (dome-firmwares.md, docs/protocols/led-dome.md), not
#: from our code: which light commands carry a brightness.
DIMS = {
    "default": True,  # L <index> <level>
    "binary": True,  # a level byte in every command
    "framed": True,  # <3,index,level> unless send_level = false
    "nab-rti-v1": False,  # <3,N>: LED N fully on
    "rtipy": False,  # T,x,y,secs: on for whole seconds
    "minirti": False,  # 0x42 + an on/off bitmask
    "elexol-24r1": False,  # port bytes: outputs on/off
    "rti-dome-m": False,  # M<n>: LED n on
    "nichlock": False,  # 0: step to the next LED
}

SERIAL_DOMES = sorted(
    p for p in CONFIGS.glob("*.toml") if "[dome.serial]" in p.read_text(encoding="utf-8")
)
ON_OFF_DOMES = [p for p in SERIAL_DOMES if not DIMS[load_rig_config(p).config.dome.serial.profile]]

#: A light calibration file for the 12-LED emulated Nab dome, every factor 0.3.
CALIBRATION = (
    'format = "rti-rig-light-calibration/1"\n'
    'rig = "emulated-nab-rti-v1"\n'
    f"intensity_correction = {[0.3] * 12}\n"
)


def said(output: str) -> str:
    return " ".join(output.split())


def test_every_built_in_firmware_declares_what_its_light_command_can_do() -> None:
    assert set(described_profiles()) <= set(DIMS)
    for name in described_profiles():
        assert "brightness" in no_dimming(name), name


@pytest.mark.parametrize("config", SERIAL_DOMES, ids=lambda p: p.name)
def test_every_shipped_dome_declares_whether_it_dims_as_its_firmware_does(config: Path) -> None:
    """The settings' fact, and the driver's the composition root builds, are the firmware's."""
    settings = load_rig_config(config).config.dome.serial
    assert settings.can_dim is DIMS[settings.profile]
    assert (settings.dimming_refusal() is None) is settings.can_dim
    assert build_driver(settings).can_dim is settings.can_dim
    link = build_dome(settings, VirtualClock()).link
    assert link.can_dim is settings.can_dim


def test_the_factory_gives_the_link_the_settings_answer(monkeypatch: pytest.MonkeyPatch) -> None:
    """The settings are the one source: the link does not ask its codec a second time."""
    settings = DomeSerialSettings(port="loop://")
    assert build_driver(settings).can_dim is True
    monkeypatch.setattr(DomeSerialSettings, "can_dim", property(lambda self: False))
    assert build_driver(settings).can_dim is False


def test_a_driver_refuses_to_say_it_dims_when_its_bytes_carry_no_level() -> None:
    framed = DomeSerialSettings(port="loop://", profile="framed", framed={"send_level": False})
    with pytest.raises(ValueError, match="cannot dim"):
        LedDomeDriver(SerialTransport("loop://"), make_codec(framed), can_dim=True)
    nab = DomeSerialSettings(port="loop://", profile="nab-rti-v1")
    with pytest.raises(ValueError, match="cannot dim"):
        ScriptedDomeDriver(SerialTransport("loop://"), protocol_for(nab), can_dim=True)


def test_the_shipped_domes_hold_both_kinds() -> None:
    names = {load_rig_config(p).config.dome.serial.profile for p in ON_OFF_DOMES}
    assert {"nab-rti-v1", "rtipy", "minirti", "elexol-24r1", "rti-dome-m", "nichlock"} <= names
    assert len(ON_OFF_DOMES) < len(SERIAL_DOMES)


@pytest.mark.parametrize("config", ON_OFF_DOMES, ids=lambda p: p.name)
def test_calibrate_lights_refuses_a_firmware_that_cannot_dim(tmp_path: Path, config: Path) -> None:
    card = tmp_path / "card"
    card.mkdir()
    out = tmp_path / "c.toml"
    profile = load_rig_config(config).config.dome.serial.profile
    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(config), "--out", str(out)])
    text = said(r.output)
    assert r.exit_code == 2, text
    assert "Traceback" not in text
    assert f"the {profile} firmware cannot dim an LED" in text, text
    assert "needs a link whose light command carries a brightness" in text, text
    assert not out.exists()


def _nab_with(tmp_path: Path, line: str) -> Path:
    """emulated_nab_rti_v1.toml with ``line`` under its [dome.serial]."""
    text = (CONFIGS / "emulated_nab_rti_v1.toml").read_text(encoding="utf-8")
    assert "\n[dome.serial]\n" in text
    text = text.replace("\n[dome.serial]\n", f"\n[dome.serial]\n{line}\n")
    return write_config(tmp_path, text, "nab.toml")


@pytest.mark.parametrize("command", ["check", "run"])
def test_a_correction_file_for_the_nab_sketch_is_refused_before_anything_lights(
    tmp_path: Path, command: str
) -> None:
    write_config(tmp_path, CALIBRATION, "c.toml")
    cfg = _nab_with(tmp_path, 'intensity_correction_file = "c.toml"')
    session = tmp_path / "s"
    args = [command, str(cfg)] + (
        ["--lights", "6", "--out", str(session)] if command == "run" else []
    )
    r = runner.invoke(app, args)
    text = said(r.output)
    assert r.exit_code == 2, text
    assert "Traceback" not in text and "PASS" not in text
    assert "key 'dome.serial.intensity_correction_file'" in text, text
    assert "'c.toml'" in text and "the nab-rti-v1 firmware cannot dim an LED" in text, text
    assert "would be ignored" in text
    assert not session.exists()


def test_a_typed_correction_is_refused_naming_its_own_key(tmp_path: Path) -> None:
    cfg = _nab_with(tmp_path, f"intensity_correction = {[0.3] * 12}")
    r = runner.invoke(app, ["check", str(cfg)])
    text = said(r.output)
    assert r.exit_code == 2, text
    assert "key 'dome.serial.intensity_correction':" in text, text
    assert "the nab-rti-v1 firmware cannot dim an LED" in text


def test_the_dome_refuses_to_connect_with_a_correction_it_cannot_apply() -> None:
    """Below the config loader (a program building the dome itself): refused before the port
    opens, since the Nab board boots lit."""
    settings = load_rig_config(CONFIGS / "emulated_nab_rti_v1.toml").config.dome.serial
    corrected = settings.model_copy(update={"intensity_correction": [0.3] * 12})
    dome = build_dome(corrected, VirtualClock())
    with pytest.raises(DeviceError, match="cannot dim an LED, so its intensity_correction"):
        dome.connect()
    assert not dome.link.port_open


class _Metered(Exception):
    pass


def _metered_at(loaded: object, monkeypatch: pytest.MonkeyPatch) -> tuple[int, list[str]]:
    """How many lights --auto-exposure's metering checks on ``loaded`` (12 planned), and its
    notes: the metering itself is stopped at its start."""
    import rti_rig.runtime.exposure_policy as policy
    from rti_rig.app.config import rig_geometry
    from rti_rig.app.usecases.session import fix_exposure
    from rti_rig.planner.uniform import plan_uniform

    asked: list[int] = []

    def fake_fix(rig, schedule, meter, recheck, probes, **how):  # type: ignore[no-untyped-def]
        asked.append(probes if recheck is not None else 1)
        raise _Metered

    monkeypatch.setattr(policy, "fix_session_exposure", fake_fix)

    class Rig:
        def __init__(self) -> None:
            self.loaded = loaded
            self.camera_config = loaded.config.camera  # type: ignore[attr-defined]
            self.lighting = UnlimitedLighting()

    notes: list[object] = []
    schedule = plan_uniform(rig_geometry(loaded), 12)  # type: ignore[arg-type]
    with pytest.raises(_Metered):
        fix_exposure(Rig(), schedule, 0.001, notes.append)  # type: ignore[arg-type]
    return asked[0], [n.text for n in notes]  # type: ignore[attr-defined]


def test_auto_exposure_never_takes_an_on_off_dome_for_evened_out(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Even with a correction on it (loaded past the config's check): it lights nothing
    evenly, so the planned six lights are metered, and the note does not send the user to
    calibrate-lights, which refuses this dome."""
    loaded = load_rig_config(CONFIGS / "emulated_nab_rti_v1.toml")
    probes, notes = _metered_at(loaded, monkeypatch)
    assert probes == 6
    assert "cannot be evened out" in notes[0] and "nab-rti-v1 firmware" in notes[0], notes
    assert "has no light calibration applied" not in notes[0]
    serial = loaded.config.dome.serial.model_copy(update={"intensity_correction": [0.3] * 12})
    dome = loaded.config.dome.model_copy(update={"serial": serial})
    corrected = loaded.model_copy(
        update={"config": loaded.config.model_copy(update={"dome": dome})}
    )
    probes, notes = _metered_at(corrected, monkeypatch)
    assert probes == 6
    assert "cannot be evened out" in notes[0]
