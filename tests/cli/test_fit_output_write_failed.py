"""An output the fit could not write is an error naming it, not a file listed as written; a path
with brackets is said as it is.

OpenCV reports a failed ``imwrite`` only by its return value: unchecked, a QA coverage map that
a full disk or a read-only folder kept from being written was still shown by qa.html. And
``plan``'s last line read a folder named ``coin [draft]`` as rich markup ("coin /plan.lp").
"""

from __future__ import annotations

import os
from pathlib import Path

import cv2
from conftest import CONFIGS
from typer.testing import CliRunner

import rti_rig.app.usecases.fit as fit_module
from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
runner = CliRunner()


def test_a_qa_map_that_could_not_be_written_fails_the_fit_by_name(
    tmp_path: Path, monkeypatch
) -> None:  # type: ignore[no-untyped-def]
    real = cv2.imwrite

    def refuse_qa_map(path: bytes, img, *args):  # type: ignore[no-untyped-def]
        # the path as OpenCV is given it: its bytes on disk (image io)
        return False if os.fsdecode(path).endswith("qa_coverage.png") else real(path, img, *args)

    monkeypatch.setattr(fit_module.cv2, "imwrite", refuse_qa_map)
    out = tmp_path / "fit"
    r = runner.invoke(app, ["fit", str(ACQ), "--out", str(out), "--no-ptm", "--no-hsh"])
    text = " ".join(r.output.split())
    assert r.exit_code != 0, r.output
    assert "could not write" in text and "qa_coverage.png" in text
    assert "Traceback" not in r.output


def test_plan_says_an_output_path_with_brackets_as_it_is(tmp_path: Path) -> None:
    folder = tmp_path / "coin [draft]"
    folder.mkdir()
    out = folder / "plan.lp"
    args = ["plan", "--rig", str(CONFIGS / "simulated_dome.toml"), "--lights", "8"]
    r = CliRunner().invoke(app, [*args, "--out", str(out)], terminal_width=400)
    assert r.exit_code == 0, r.output
    assert f"→ {out}" in " ".join(r.output.split())
