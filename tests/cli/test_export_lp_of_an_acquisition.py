"""`export-lp` and `run --resume` given a recorded acquisition (an `.lp` with its images, no
session): said to be used as it is, with the command that does.

Why: `export-lp ACQ/dirs.lp` was told to "give the session folder that holds it (the one with
manifest.json)", and that folder was then refused as "not an rti-rig session folder": a loop
that never said an acquisition's `.lp` is fitted and replayed as it is."""

from __future__ import annotations

import re
import shlex
import shutil
from pathlib import Path

import pytest
from conftest import REPO, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.fixture
def acquisition(tmp_path: Path) -> Path:
    acq = tmp_path / "acq"
    shutil.copytree(REPO / "tests" / "data" / "neuralrti_replay", acq)
    return acq


@pytest.mark.parametrize(
    "argv",
    [
        ["export-lp", "{lp}", "--out", "{tmp}/x.lp"],
        ["export-lp", "{acq}", "--out", "{tmp}/x.lp"],
        ["run", "--resume", "{lp}"],
        ["run", "--resume", "{acq}"],
    ],
)
def test_an_acquisition_is_told_to_be_used_as_it_is(
    acquisition: Path, tmp_path: Path, argv: list[str]
) -> None:
    lp = acquisition / "dirs.lp"
    args = [a.format(lp=lp, acq=acquisition, tmp=tmp_path) for a in argv]
    r = runner.invoke(app, args)
    text = said(r)
    assert r.exit_code == 2, text
    assert "Traceback" not in r.output and not (tmp_path / "x.lp").exists()
    assert "give the session folder that holds it" not in text
    assert "recorded acquisition's .lp" in text
    # folders that do not exist yet beside it (``--out DIR``, pasted, had made DIR)
    fit_out, out = acquisition / "dirs-fit", acquisition / "dirs-replay"
    assert f"rti-rig fit {shlex.quote(str(lp))} --out {shlex.quote(str(fit_out))}" in text
    # the replay command it names runs as printed, into the folder it names
    found = re.search(r"rti-rig (run \S+ --out \S+)", text)
    assert found is not None, text
    assert found.group(1) == f"run {shlex.quote(str(lp))} --out {shlex.quote(str(out))}", text
    run = runner.invoke(app, shlex.split(found.group(1)))
    assert run.exit_code == 0, said(run)
    assert (out / "lights.lp").read_text().splitlines()[0] == "18"
