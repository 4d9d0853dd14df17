"""The guide's sample of ``rti-rig check rig_configs/emulated_dome.toml`` shows the lines the
command prints, in order: a reader compares their own check with it line by line. The sample
had lacked the round-trip, recovery and lights lines, then the "Checking …" line the command
prints first."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "guide.md"


def _first_words(lines: list[str]) -> list[str]:
    return [line.split()[0] for line in lines if line.strip()]


def test_the_guides_check_sample_has_the_lines_the_check_prints(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    cli_app = importlib.import_module("rti_rig.cli.app")  # the module, not the Typer app
    monkeypatch.setattr(cli_app.out, "_width", 400)  # one printed line, one line here
    text = GUIDE.read_text(encoding="utf-8")
    found = re.search(
        r"Rehearsed on the emulated dome \(`rti-rig check rig_configs/emulated_dome\.toml`\):"
        r"\s*```\n(.*?)```",
        text,
        re.S,
    )
    assert found, "the guide's check sample is gone"
    sample = found.group(1).splitlines()
    r = CliRunner().invoke(app, ["check", str(CONFIGS / "emulated_dome.toml")], terminal_width=400)
    assert r.exit_code == 0, r.output
    printed = [line for line in r.output.splitlines() if not line.startswith("note:")]
    assert _first_words(sample) == _first_words(printed), (sample, r.output)
