"""The QA verdict after a session on an uncalibrated dome: an image its LED's own output makes
brighter is no reshoot but a reason to run ``rti-rig calibrate-lights``; on a calibrated dome,
an arm or a dome that cannot dim its LEDs, the reshoot stands. Through the CLI on the shipped
emulated card dome (whose LEDs differ, 20 % RMS) and on it calibrated with one LED flashing
brighter than its calibration (a stray flash)."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import CONFIGS, write_config
from typer.testing import CliRunner

from rti_rig.app.config import EmulatorConfig
from rti_rig.app.usecases.uneven_lights import with_uneven_lights
from rti_rig.cli import app
from rti_rig.reconstruct.qa import QAReport, assess
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals

runner = CliRunner()
N, BRIGHT = 36, 20


@pytest.fixture(scope="module")
def report() -> QAReport:
    """A matte sphere under uneven lights (20 % RMS), image_021's light 1.9× nominal."""
    lights = fibonacci_lights(N)
    normals, _ = sphere_normals(96, 96)
    gains = np.exp(0.2 * np.random.default_rng(1).standard_normal(N))
    gains[BRIGHT] = 1.9
    images = render(normals, 0.5, lights) * gains[:, None, None]
    frames = [np.clip(im * 0.5 * 65535, 0, 65535).astype(np.uint16) for im in images]
    qa = assess(frames, lights, [f"image_{i + 1:03d}" for i in range(N)])
    assert [c.index for c in qa.reshoot] == [BRIGHT]
    return qa


def _manifest(kind: str = "dome", serial: dict[str, Any] | None = None) -> dict[str, Any]:
    dome = {"layout": "lp", **({"serial": serial} if serial is not None else {})}
    config = {"dome": dome} if kind == "dome" else {"arm": {}}
    return {"rig": {"kind": kind, "backend": "emulated", "config": config}}


def test_an_uncalibrated_serial_dome_is_told_to_calibrate_not_to_reshoot(report: QAReport) -> None:
    qa = with_uneven_lights(report, _manifest(serial={"port": "x", "profile": "default"}))
    assert qa.good
    verdict = qa.verdict
    assert verdict.startswith("no image to reshoot, but the dome's LEDs are uneven: image_021 (")
    assert "brighter than the other images predict" in verdict
    assert "no light calibration applied" in verdict
    assert "rti-rig calibrate-lights" in verdict
    assert re.search(r"\(\d+ % RMS from image to image", verdict), verdict


@pytest.mark.parametrize(
    "manifest",
    [
        _manifest(serial={"port": "x", "intensity_correction": [1.0] * N}),  # calibrated
        _manifest(serial={"port": "x", "intensity_correction_file": "cal.toml"}),
        _manifest(serial=None),  # a simulated dome: no serial link to dim its LEDs by
        _manifest(kind="arm"),  # one lamp for every image
        {},  # no manifest worth the name
    ],
    ids=["calibrated", "calibration file", "no serial", "arm", "empty"],
)
def test_elsewhere_the_reshoot_stands(report: QAReport, manifest: dict[str, Any]) -> None:
    qa = with_uneven_lights(report, manifest)
    assert qa is report and qa.verdict.startswith("reshoot: image_021 (")


def _verdict(output: str) -> str:
    text = " ".join(output.split())
    return text[text.index("QA verdict:") :]


@pytest.mark.slow
@pytest.mark.pty
@pytest.mark.e2e
def test_the_shipped_card_dome_advises_calibrate_lights(tmp_path: Path) -> None:
    """Before: "QA verdict: reshoot: image_039 (1.6× brighter than the other images predict)",
    the LED the emulator draws 1.58× the median's."""
    out = tmp_path / "card"
    r = runner.invoke(app, ["run", str(CONFIGS / "emulated_dome_card.toml"), "--out", str(out)])
    assert r.exit_code == 0, r.output
    verdict = _verdict(r.output)
    assert verdict.startswith(
        "QA verdict: no image to reshoot, but the dome's LEDs are uneven: image_039 (1.6×) is "
        "brighter than the other images predict"
    ), verdict
    assert "rti-rig calibrate-lights" in verdict and "reshoot:" not in verdict


@pytest.mark.slow
@pytest.mark.pty
@pytest.mark.e2e
def test_a_stray_flash_on_the_calibrated_card_dome_is_still_to_reshoot(tmp_path: Path) -> None:
    """The same dome with the correction for its true LED outputs applied, and LED 20 flashing
    1.8× what that correction expects: a reshoot, not a calibration."""
    power = EmulatorConfig(led_power_spread=0.2).led_powers(48, 0)
    correction = power.min() / power
    flashed = power.copy()
    flashed[20] *= 1.8
    text = (CONFIGS / "emulated_dome_card.toml").read_text(encoding="utf-8")
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    text = text.replace("width = 256", "width = 96").replace("height = 256", "height = 96")
    text = re.sub(
        r"led_power_spread = 0\.2.*",
        f"led_power = [{', '.join(f'{p:.6f}' for p in flashed)}]",
        text,
    )
    factors = ", ".join(f"{c:.6f}" for c in correction)
    text = text.replace(
        'profile = "default"\n', f'profile = "default"\nintensity_correction = [{factors}]\n'
    )
    cfg = write_config(tmp_path, text)
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "s")])
    assert r.exit_code == 0, r.output
    verdict = _verdict(r.output)
    assert re.match(
        r"QA verdict: reshoot: image_021 \(1\.\d× brighter than the other images predict\)",
        verdict,
    ), verdict
    assert "calibrate-lights" not in verdict
