"""A camera that cannot say when its exposure is over holds its LED lit through the transfer.

The dry run's simulated camera (and an OpenCV camera) returns its frame after the settle, the
exposure, the readout and the transfer, and only then is the LED switched off. The load-time
check of ``[camera] exposure_s`` against ``[dome.serial.thermal] max_on_s`` counted the settle,
the exposure and the readout only: the shipped emulated dome with max_on_s = 0.46 s was
accepted, and `rti-rig run` stopped at its first image ("LED 0 stayed on 1.153 s, beyond
max_on_s = 0.46 s; the firmware watchdog switched it off"), the dome opened and lit.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import CONFIGS, write_config
from typer.testing import CliRunner

from rti_rig.app.config import ConfigError, load_rig_config
from rti_rig.cli import app


def emulated_dome(tmp_path: Path, max_on_s: float) -> Path:
    """The shipped emulated dome (settle 0.1, exposure 0.05, readout 0.3, transfer 0.7 s, and
    the all-off's 0.02 s: a shot holds its LED 1.17 s) with a thermal limit."""
    text = (CONFIGS / "emulated_dome.toml").read_text()
    for line in ("settle_s = 0.1\n", "readout_s = 0.3\n", "transfer_s = 0.7\n"):
        assert line in text
    assert "exposure_s = 0.05\n" in text and "[dome.serial.thermal]" not in text
    text = text.replace('"example_dome_48.lp"', f'"{(CONFIGS / "example_dome_48.lp").as_posix()}"')
    text = text.replace(
        "[camera]", f"[dome.serial.thermal]\nmax_on_s = {max_on_s}\nmax_duty = 0.5\n\n[camera]", 1
    )
    return write_config(tmp_path, text, "dome.toml")


def test_a_shot_held_lit_through_its_transfer_past_max_on_s_is_refused_at_load(
    tmp_path: Path,
) -> None:
    with pytest.raises(ConfigError) as e:
        load_rig_config(emulated_dome(tmp_path, 1.0))
    assert e.value.key == "camera.exposure_s"
    said = str(e.value)
    assert "[dome.serial.thermal] max_on_s = 1 s" in said
    assert (
        "timing.settle_s 0.1 + camera.exposure_s 0.05 + timing.readout_s 0.3 + "
        "timing.transfer_s 0.7 + timing.light_switch_s 0.02 (this camera cannot say when its "
        "exposure is over" in said
    )
    assert "= 1.17 s" in said


def test_a_shot_that_fits_with_its_transfer_runs_to_the_end(tmp_path: Path) -> None:
    """The limit the check now sets is the one the run meets: at max_on_s = 1.2 s every image
    is taken (its LED lit about 1.15 s each, the all-off's time on top)."""
    out = tmp_path / "s"
    args = ["run", str(emulated_dome(tmp_path, 1.2)), "--out", str(out), "--lights", "3"]
    result = CliRunner().invoke(app, [*args, "--no-verdict"])
    assert result.exit_code == 0, result.output
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] == "completed"
