"""`calibrate-lights` names as the LEDs' extremes only LEDs its card session measured.

Why: with a correction in force, an LED the card session did not shoot is assumed at the
figure the correction in force gives it; the report had named such an LED as the brightest
("Each LED's own light, without the correction, is still 0.74 (LED 18 ...) to 1.58 (LED 38,
led_38.jpg) of the median" from a 12-LED card session that never lit LED 38).
"""

from __future__ import annotations

import re
from pathlib import Path

from card_support import TRUE_POWER, card_rig, shoot
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, read_lp, write_lp

runner = CliRunner()


def test_a_partial_card_session_under_a_correction_names_only_measured_leds(
    tmp_path: Path,
) -> None:
    full = tmp_path / "card"
    shoot(card_rig(tmp_path), full)
    correction = tmp_path / "correction.toml"
    rig = str(tmp_path / "card.toml")
    r = runner.invoke(app, ["calibrate-lights", str(full), "--rig", rig, "--out", str(correction)])
    assert r.exit_code == 0, r.output
    cfg = card_rig(tmp_path, 'intensity_correction_file = "correction.toml"\n', "cal.toml")
    brightest, weakest = int(TRUE_POWER.argmax()), int(TRUE_POWER.argmin())
    leds = [i for i in range(0, 48, 4) if i not in (brightest, weakest)]
    dome = read_lp(CONFIGS / "example_dome_48.lp")
    plan = tmp_path / "plan.lp"
    write_lp(
        plan, [LpEntry(f"image_{k + 1:03d}.jpg", dome[i].direction) for k, i in enumerate(leds)]
    )
    part = tmp_path / "part"
    r = runner.invoke(app, ["run", str(cfg), "--plan", str(plan), "--out", str(part)])
    assert r.exit_code == 0, r.output

    r = runner.invoke(
        app,
        ["calibrate-lights", str(part), "--rig", str(cfg), "--out", str(tmp_path / "again.toml")],
    )

    assert r.exit_code == 0, r.output
    text = said(r)
    sentence = re.search(r"own light, without the correction, is still .*? of the median", text)
    assert sentence is not None, text
    named = [int(n) for n in re.findall(r"\(LED (\d+),", sentence.group(0))]
    assert named and set(named) <= set(leds), sentence.group(0)
    assert "Each measured LED's own light" in text
