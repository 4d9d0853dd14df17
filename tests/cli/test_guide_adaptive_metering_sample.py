"""The guide's section 10 tells a reader how to meter an adaptive session's exposure with the
command the refusal of ``run --adaptive --auto-exposure`` advises: run on a shipped config,
that refusal's command is the guide's, its ``RIG.toml`` and ``DIR`` the ones given.

Why: the guide showed ``--out TEST`` after the refusal had come to advise a folder not there
yet beside the session's (``DIR-metering``: a ``TEST`` left by an earlier metering run was
refused), and no test read the sample."""

from __future__ import annotations

import re
from pathlib import Path

from conftest import CONFIGS, REPO, said
from typer.testing import CliRunner

from rti_rig.cli import app

GUIDE = REPO / "docs" / "guide.md"


def _section_10() -> str:
    text = GUIDE.read_text(encoding="utf-8")
    found = re.search(r"^## 10\. .*?\n(.*?)^## 11\.", text, re.S | re.M)
    assert found, "the guide's section 10 is gone"
    return " ".join(found.group(1).split())


def test_the_guides_metering_command_is_the_one_the_refusal_advises(tmp_path: Path) -> None:
    section = _section_10()
    adaptive = re.search(r"`rti-rig run (RIG\.toml --out DIR --adaptive[^`]*)`", section)
    metering = re.search(r"`(rti-rig run RIG\.toml --out [^`]*--auto-exposure)` prints", section)
    assert adaptive and metering, "the guide's adaptive metering sample is gone"
    rig, out = CONFIGS / "simulated_dome.toml", tmp_path / "DIR"
    args = [str(rig) if a == "RIG.toml" else a for a in adaptive.group(1).split()]
    args = [str(out) if a == "DIR" else a for a in args]
    r = CliRunner().invoke(app, ["run", *args, "--auto-exposure"])
    text = " ".join(said(r).split())
    assert r.exit_code == 2 and "Traceback" not in r.output, text
    advised = re.search(r"Meter once with a planned run \((rti-rig run .*?--auto-exposure)", text)
    assert advised, text
    shown = metering.group(1).replace("RIG.toml", str(rig)).replace("DIR", str(out))
    assert advised.group(1) == shown, (advised.group(1), metering.group(1))
    assert not out.exists()
