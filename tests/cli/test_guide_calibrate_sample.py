"""The guide's sample of ``rti-rig calibrate-lights`` (section 6) shows the lines the command
prints on the shipped card dome, in order, with its figures: a reader compares their own
calibration with it line by line. Walking the guide found the sample without the "Card session"
line the command prints first, the session image beside each extreme LED, the config line split
from the key, and the closing "Then shoot the card again" line."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "guide.md"
SHIPPED = CONFIGS / "emulated_dome_card.toml"


def _sample() -> list[str]:
    text = GUIDE.read_text(encoding="utf-8")
    found = re.search(
        r"Rehearsed on the emulated dome with uneven LEDs, `rig_configs/emulated_dome_card\.toml`"
        r".*?```\n(.*?)```",
        text,
        re.S,
    )
    assert found, "the guide's calibrate-lights sample is gone"
    return [line for line in found.group(1).splitlines() if line.strip()]


def test_the_guides_calibrate_sample_is_what_the_shipped_card_dome_prints(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cli_app = importlib.import_module("rti_rig.cli.app")  # the module, not the Typer app
    monkeypatch.setattr(cli_app.out, "_width", 400)  # one printed line, one line here
    monkeypatch.chdir(tmp_path)  # the sample's relative `sessions/card`
    runner = CliRunner()
    r = runner.invoke(app, ["run", str(SHIPPED), "--out", "sessions/card", "--no-verdict"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(
        app, ["calibrate-lights", "sessions/card", "--rig", str(SHIPPED)], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    printed = [line for line in r.output.splitlines() if line.strip()]
    sample = _sample()
    assert [s.split()[0] for s in sample] == [p.split()[0] for p in printed], (sample, r.output)
    # Every line but the two naming this machine's paths is printed as the guide shows it.
    for shown, got in zip(sample, printed, strict=True):
        if shown.startswith(("To use it", "intensity_correction_file")):
            continue
        assert shown == got, (shown, got)
