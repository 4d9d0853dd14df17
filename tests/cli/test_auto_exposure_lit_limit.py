"""`run --auto-exposure` on a dome with max_on_s and a camera that holds its LED lit until its
frame is in (the emulated dome's simulated camera: each shot holds its LED settle + exposure +
readout + transfer, 1.1 s + the exposure).

The emulator's own record of what it lit is the truth; the runs are on the dry run's virtual
clock (nothing here depends on how long anything takes).
"""

from __future__ import annotations

import json
from pathlib import Path

from conftest import CONFIGS, said, write_config
from typer.testing import CliRunner

import rti_rig.app.compose as compose
from rti_rig.cli import app


def emulated_dome(tmp_path: Path, max_on_s: float, led_power: float | None = None) -> Path:
    """The shipped emulated dome with a thermal limit (and, if given, every LED that dim)."""
    text = (CONFIGS / "emulated_dome.toml").read_text()
    text = text.replace('"example_dome_48.lp"', f'"{(CONFIGS / "example_dome_48.lp").as_posix()}"')
    text = text.replace(
        "[camera]", f"[dome.serial.thermal]\nmax_on_s = {max_on_s}\nmax_duty = 0.5\n\n[camera]", 1
    )
    if led_power is not None:
        assert "[emulator]" not in text
        text += f"\n[emulator]\nled_power = [{', '.join([str(led_power)] * 48)}]\n"
    return write_config(tmp_path, text, "dome.toml")


def lightings(monkeypatch) -> list:  # type: ignore[no-untyped-def]
    """Each rig the command builds: its emulated firmware (to read what it lit)."""
    firmwares: list = []
    real_build = compose.build_rig

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real_build(*args, **kwargs)
        firmwares.append(rig.emulator)
        return rig

    monkeypatch.setattr(compose, "build_rig", build)
    return firmwares


def test_metering_takes_each_test_shot_under_its_own_lighting_within_max_on_s(
    tmp_path: Path, monkeypatch
) -> None:
    """max_on_s = 2 s holds one shot (1.2 s), not a series: metering had shot its series at
    the brightest light under one lighting and stopped at the thermal guard before the session
    began ("LED 41 stayed on 2.235 s, beyond max_on_s = 2 s; the firmware watchdog switched it
    off")."""
    firmwares = lightings(monkeypatch)
    out = tmp_path / "s"
    args = [str(emulated_dome(tmp_path, 2.0)), "--out", str(out), "--lights", "6"]
    result = CliRunner().invoke(app, ["run", *args, "--auto-exposure", "--no-verdict"])
    assert result.exit_code == 0, said(result)
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] == "completed"
    metering = firmwares[0]
    shots = manifest["schedule"]["provenance"]["exposure"]["metering_shots"]
    lit = [ev.index for ev in metering.history if ev.what == "lit"]
    assert len(lit) >= shots > len(set(lit))  # a series at one light, one lighting a shot
    assert not [ev for ev in metering.history if ev.what == "watchdog"]


def test_metering_a_dim_dome_chooses_no_exposure_its_held_shot_cannot_fit(
    tmp_path: Path, monkeypatch
) -> None:
    """Every LED at 5 % of its output: metering goes to the longest exposure it may choose.
    That had left settle and readout only (1.6 s at max_on_s = 2 s), and the test shot, which
    holds its LED through the transfer too, stopped at the thermal guard ("LED 41 stayed on
    2.691 s, beyond max_on_s = 2 s"). The cap now leaves the transfer and the all-off's time
    (timing.light_switch_s, 0.3 s here: room for the pty's own time under any load) too."""
    config = emulated_dome(tmp_path, 2.0, led_power=0.05)
    text = config.read_text()
    assert "light_switch_s = 0.02\n" in text
    config.write_text(text.replace("light_switch_s = 0.02\n", "light_switch_s = 0.3\n"))
    out = tmp_path / "s"
    args = [str(config), "--out", str(out), "--lights", "6", "--auto-exposure", "--no-verdict"]
    result = CliRunner().invoke(app, ["run", *args])
    text = said(result)
    assert result.exit_code == 0, text
    steps = json.loads((out / "manifest.json").read_text())["schedule"]["steps"]
    (exposure,) = {s["exposure_s"] for s in steps}
    assert exposure <= 2.0 - 0.1 - 0.3 - 0.7 - 0.3 + 1e-9
    assert "is the longest the metering could choose" in text
    assert "less timing.settle_s, readout_s, transfer_s and light_switch_s" in text
