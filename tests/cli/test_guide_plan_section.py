"""The guide's section 5 says what `preview` and `plan` print on the shipped simulated dome: the
LED the default preview light falls on (and its distance), the one chosen within a 45° band,
and plan's first line, which a reader compares with their own. No test had read them: a
change to the dome, the preview's default light or the report's wording would have left the
guide quoting what the commands no longer print."""

from __future__ import annotations

import re
from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "guide.md"
RIG = CONFIGS / "simulated_dome.toml"


def _section_5() -> str:
    text = GUIDE.read_text(encoding="utf-8")
    found = re.search(r"## 5\. Plan the lights from a preview\n(.*?)\n## 6\.", text, re.S)
    assert found, "the guide's section 5 is gone"
    return " ".join(found.group(1).split())


def test_the_guides_preview_and_plan_claims_are_what_the_shipped_dome_prints(
    tmp_path: Path,
) -> None:
    guide = _section_5()
    nearest = re.search(r"here `(LED \d+)`, ([\d.]+)° away", guide)
    banded = re.search(r"chosen within it \(here `(LED \d+)`, at ([\d.]+)°\)", guide)
    first_line = re.search(r"prints what it assumed and what it expects, e\.g\. `([^`]+)`", guide)
    assert nearest and banded and first_line, guide

    runner = CliRunner()
    r = runner.invoke(app, ["preview", str(RIG), "--out", str(tmp_path / "preview")])
    assert r.exit_code == 0, r.output
    assert f"{nearest.group(1)} (" in said(r), r.output
    assert f"is {nearest.group(2)}° away" in said(r), r.output

    r = runner.invoke(
        app,
        ["preview", str(RIG), "--out", str(tmp_path / "p45"), "--max-elevation-deg", "45"],
    )
    assert r.exit_code == 0, r.output
    assert re.search(rf"{banded.group(1)} \(az [\d.]+°, el {banded.group(2)}(\.0)?°\)", said(r)), (
        r.output
    )

    plan = tmp_path / "plan.lp"
    r = runner.invoke(
        app,
        [
            "plan",
            str(tmp_path / "preview"),
            "--rig",
            str(RIG),
            "--lights",
            "12",
            "--out",
            str(plan),
        ],
    )
    assert r.exit_code == 0, r.output
    assert said(r).startswith(first_line.group(1)), (first_line.group(1), r.output)
    assert plan.read_text().splitlines()[0] == "12"
