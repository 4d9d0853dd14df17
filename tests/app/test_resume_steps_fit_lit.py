"""A metered session's own exposures are checked against max_on_s before the port opens.

`run --auto-exposure` fixes each step's exposure_s in the session's schedule; a resume shoots
the steps left at those exposures. The config's exposure_s is checked against
``[dome.serial.thermal] max_on_s`` when the config loads, the steps' were not: a session
metered at 0.084 s, its config's max_on_s then lowered to 1.17 s (each shot of the emulated
dome's simulated camera holds its LED 1.1 s + the exposure), was resumed: the dome opened, LED
21 lit, and the run stopped at the thermal guard ("LED 21 stayed on 1.186 s, beyond max_on_s =
1.17 s; the firmware watchdog switched it off"), advising a resume that did the same.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from conftest import CONFIGS, cut_new_session, said, write_config
from typer.testing import CliRunner

import rti_rig.app.compose as compose
from rti_rig.app.usecases.session import NewSessionRequest
from rti_rig.cli import app
from rti_rig.runtime.controller import FinishReason

pytestmark = pytest.mark.pty


def emulated_dome(tmp_path: Path, max_on_s: float) -> Path:
    """The shipped emulated dome with a thermal limit (written in place)."""
    text = (CONFIGS / "emulated_dome.toml").read_text()
    text = text.replace('"example_dome_48.lp"', f'"{(CONFIGS / "example_dome_48.lp").as_posix()}"')
    text = text.replace(
        "[camera]", f"[dome.serial.thermal]\nmax_on_s = {max_on_s}\nmax_duty = 0.5\n\n[camera]", 1
    )
    return write_config(tmp_path, text, "dome.toml")


def metered_and_stopped(tmp_path: Path) -> tuple[Path, Path, float]:
    """A 6-light session metered with --auto-exposure and stopped after 2 images."""
    cfg = emulated_dome(tmp_path, 8.0)
    out = tmp_path / "s"
    request = NewSessionRequest(cfg, out, lights=6, auto_exposure=True)
    assert cut_new_session(request, after_step=1).finish_reason is FinishReason.CANCELLED
    steps = json.loads((out / "manifest.json").read_text())["schedule"]["steps"]
    (exposure,) = {s["exposure_s"] for s in steps}
    return cfg, out, exposure


def test_a_resume_whose_steps_overrun_max_on_s_is_refused_before_the_port_opens(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg, out, exposure = metered_and_stopped(tmp_path)
    held = 0.1 + 0.3 + 0.7 + 0.02  # settle, readout, transfer, all-off: the emulated dome
    # a limit the config's own 0.05 s fits and the metered exposure does not
    max_on = round(held + (0.05 + exposure) / 2, 3)
    assert held + 0.05 < max_on < held + exposure
    emulated_dome(tmp_path, max_on)  # the same file, edited
    built: list[object] = []
    real_build = compose.build_rig

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        built.append(args)
        return real_build(*args, **kwargs)

    monkeypatch.setattr(compose, "build_rig", build)
    result = CliRunner().invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    text = said(result)
    assert result.exit_code == 2, result.output
    assert not built  # nothing was opened, lit or moved
    led = json.loads((out / "manifest.json").read_text())["schedule"]["steps"][2]["led"]
    assert "4 step(s) to shoot expose too long" in text
    assert f"[dome.serial.thermal] max_on_s = {max_on:g} s ({cfg.resolve()})" in text
    shot = f"timing.settle_s 0.1 + its exposure_s {round(exposure, 6):g}"
    # the LED by its number and direction (the dome's id for it, led_021, is not said)
    assert re.search(rf"step 3 \(LED {led}, (\S+\.jpg, )?az [\d.]+°, el [\d.]+°\), ", text), text
    assert f"), {shot}" in text
    assert "nothing has moved" in text and "raise max_on_s to at least" in text
    assert len((out / "journal.jsonl").read_text().splitlines()) == 2  # nothing added

    emulated_dome(tmp_path, 8.0)  # set back: the resume finishes the session
    result = CliRunner().invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert result.exit_code == 0, result.output
    assert len((out / "journal.jsonl").read_text().splitlines()) == 6
