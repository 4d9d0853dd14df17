"""`run --adaptive` in a band that holds no light beyond the 4 of the start is refused with the
planned run to use instead: that run keeps to the band (it had been the bare `rti-rig run RIG
--out DIR`, which fires every LED of the dome, those the band kept out too)."""

from __future__ import annotations

import math
import shlex
from pathlib import Path

from conftest import SMALL_DOME, journal, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_the_advised_planned_run_keeps_to_the_band(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)  # 8 LEDs at 20°, 4 at 50°
    r = runner.invoke(
        app,
        ["run", str(cfg), "--out", str(tmp_path / "s"), "--adaptive", "--min-elevation-deg", "45"],
    )
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "none left to choose" in text
    advised = text.split("shoot its 4 with a planned run: ", 1)[1]
    # the run's own --out, nothing written to it (--out DIR, pasted, made a folder named DIR)
    assert advised == f"rti-rig run {cfg} --out {tmp_path / 's'} --lights 4 --min-elevation-deg 45"
    argv = shlex.split(advised)[1:]
    r = runner.invoke(app, [*argv, "--no-verdict"])
    assert r.exit_code == 0, r.output
    steps = journal(tmp_path / "s")
    assert len(steps) == 4
    assert all(math.degrees(math.asin(s["actual_direction"][2])) > 45 for s in steps)


def test_the_advised_metering_run_keeps_to_the_band(tmp_path: Path) -> None:
    """`--auto-exposure` with `--adaptive --max-elevation-deg 45` (a gilded object): the
    metering run advised had been `--lights 6` over every elevation, metering under (and
    firing) lights above the ceiling that the session will never fire."""
    cfg = write_config(tmp_path, SMALL_DOME)
    r = runner.invoke(
        app,
        [
            "run",
            str(cfg),
            "--out",
            str(tmp_path / "s"),
            *("--adaptive", "--lights", "6", "--max-elevation-deg", "30", "--auto-exposure"),
        ],
    )
    assert r.exit_code == 2, r.output
    metering = tmp_path / "s-metering"
    assert (
        f"rti-rig run {cfg} --out {metering} --lights 6 --max-elevation-deg 30 --auto-exposure"
        in said(r)
    )
    assert "then run this command again without --auto-exposure" in said(r)
    assert not (tmp_path / "s").exists()
