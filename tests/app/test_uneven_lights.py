"""The QA verdict after a session on an uncalibrated dome: an image its LED's own output makes
brighter is no reshoot but a reason to run ``rti-rig calibrate-lights``; on a calibrated dome,
an arm or a dome with no serial link to dim its LEDs, the reshoot stands. On a dome whose
firmware cannot dim an LED (nab-rti-v1, …) it is no reshoot either, and the verdict says the
firmware cannot even it out instead of advising ``calibrate-lights`` (which refuses such a
dome). Through the CLI on the shipped emulated card dome (whose LEDs differ, 20 % RMS), on it
calibrated with one LED flashing brighter than its calibration (a stray flash), and on the
shipped emulated nab-rti-v1 dome given uneven LEDs."""

from __future__ import annotations

import re
import shlex
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import CONFIGS, write_config
from typer.testing import CliRunner

from rti_rig.app.config import EmulatorConfig, load_rig_config
from rti_rig.app.usecases.uneven_lights import recorded_dimming_refusal, with_uneven_lights
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


#: Each profile, as recorded in a session's [dome.serial], and whether its link can dim an LED
#: (the firmwares' published light commands: docs/protocols/led-dome.md, dome-firmwares.md).
RECORDED_SERIAL = {
    "default": ({"port": "x", "profile": "default"}, True),
    "no profile (older table)": ({"port": "x"}, True),
    "binary": ({"port": "x", "profile": "binary"}, True),
    "framed": ({"port": "x", "profile": "framed"}, True),
    "framed send_level": ({"port": "x", "profile": "framed", "framed": {"send_level": True}}, True),
    "framed no level": (
        {"port": "x", "profile": "framed", "framed": {"send_level": False}},
        False,
    ),
    "nab-rti-v1": ({"port": "x", "profile": "nab-rti-v1"}, False),
    "rtipy": ({"port": "x", "profile": "rtipy"}, False),
    "minirti": ({"port": "x", "profile": "minirti"}, False),
    "elexol-24r1": ({"port": "x", "profile": "elexol-24r1"}, False),
    "rti-dome-m": ({"port": "x", "profile": "rti-dome-m"}, False),
    "nichlock": ({"port": "x", "profile": "nichlock"}, False),
    "custom": ({"port": "x", "profile": "custom", "protocol": {"name": "x"}}, False),
    "unknown profile": ({"port": "x", "profile": "gone-since"}, False),
    # an older session's correction on an on/off link, never applied (now refused at load)
    "nab-rti-v1 corrected": (
        {"port": "x", "profile": "nab-rti-v1", "intensity_correction": [1.0] * N},
        False,
    ),
}


@pytest.mark.parametrize("recorded", RECORDED_SERIAL, ids=str)
def test_the_verdict_advises_calibrate_lights_only_where_the_link_can_dim(
    report: QAReport, recorded: str
) -> None:
    serial, dims = RECORDED_SERIAL[recorded]
    qa = with_uneven_lights(report, _manifest(serial=serial))
    verdict = qa.verdict
    # either way the bright image is its LED's own light, which a reshoot repeats
    assert qa.good and "reshoot:" not in verdict, verdict
    assert verdict.startswith("no image to reshoot, but the dome's LEDs are uneven: image_021 (")
    if dims:
        assert "even out the LEDs with rti-rig calibrate-lights" in verdict, verdict
        assert recorded_dimming_refusal(_manifest(serial=serial)) is None
    else:
        assert "calibrate-lights" not in verdict, verdict
        why = recorded_dimming_refusal(_manifest(serial=serial))
        assert why is not None and why in verdict, verdict
        profile = serial["profile"]
        assert f"'{profile}'" in why or f"the {profile} firmware" in why, why
        assert "no light correction can even it out" in verdict
        assert "apply_light_gains" in verdict and "card under every LED" in verdict


SERIAL_DOMES = sorted(
    p for p in CONFIGS.glob("*.toml") if "[dome.serial]" in p.read_text(encoding="utf-8")
)


@pytest.mark.parametrize("config", SERIAL_DOMES, ids=lambda p: p.name)
def test_a_recorded_table_is_judged_as_the_loaded_settings_are(config: Path) -> None:
    """The manifest records the config as written (``rig.config``): read from it, each shipped
    dome gets the answer its loaded settings give (``calibrate-lights`` refuses by)."""
    loaded = load_rig_config(config)
    manifest = {"rig": {"kind": "dome", "config": loaded.raw}}
    assert recorded_dimming_refusal(manifest) == loaded.config.dome.serial.dimming_refusal()


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
def test_the_calibrate_lights_the_verdict_gives_pastes(tmp_path: Path) -> None:
    """Before: "even out the LEDs with rti-rig calibrate-lights (a card shot under every LED;
    docs/guide.md, section 6)", a command that pasted is refused (no card session, no --rig).
    The commands now name the recorded rig config and a card folder beside the session; on
    the card dome's own session (a card, as the verdict allows), the one for this session
    pasted back measures the LEDs."""
    out = tmp_path / "my card"
    config = CONFIGS / "emulated_dome_card.toml"
    r = runner.invoke(app, ["run", str(config), "--out", str(out)], terminal_width=2000)
    assert r.exit_code == 0, r.output
    verdict = _verdict(r.output)
    shoot = f"rti-rig run {config} --out {shlex.quote(str(tmp_path / 'my card-card'))}"
    assert shoot in verdict, verdict
    measure = re.search(
        r"if this session is such a card: rti-rig (calibrate-lights .*?); ", verdict
    )
    assert measure, verdict
    words = shlex.split(measure.group(1))
    assert words == ["calibrate-lights", str(out), "--rig", str(config)], words
    done = runner.invoke(app, [*words, "--out", str(tmp_path / "cal.toml")])
    assert done.exit_code == 0, done.output
    assert (tmp_path / "cal.toml").is_file()


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


@pytest.mark.slow
@pytest.mark.pty
@pytest.mark.e2e
def test_the_nab_dome_with_uneven_leds_is_not_sent_to_calibrate_lights(tmp_path: Path) -> None:
    """Before: "... which a reshoot repeats: even out the LEDs with rti-rig calibrate-lights",
    a command that refuses the nab-rti-v1 sketch (it cannot dim an LED). The shipped emulated
    nab dome with its LEDs 0.7–1.3 of nominal and LED 5 at 2.0 (the emulator lights a firmware
    dome's LED at its own output, as the card dome's)."""
    power = [0.7, 1.3, 0.75, 1.25, 2.0, 0.8, 1.2, 0.72, 1.28, 0.85, 1.15, 1.0]
    text = (CONFIGS / "emulated_nab_rti_v1.toml").read_text(encoding="utf-8")
    assert "[emulator]" not in text and "count = 12" in text
    cfg = write_config(tmp_path, text + f"\n[emulator]\nled_power = {power}\n")
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "s")])
    assert r.exit_code == 0, r.output
    verdict = _verdict(r.output)
    assert verdict.startswith(
        "QA verdict: no image to reshoot, but the dome's LEDs are uneven: image_005 ("
    ), verdict
    assert "calibrate-lights" not in verdict and "reshoot:" not in verdict, verdict
    assert "the nab-rti-v1 firmware cannot dim an LED" in verdict, verdict
    assert "apply_light_gains" in verdict
