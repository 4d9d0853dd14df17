"""An image that is another light's picture again (a frame delivered twice, a file copied
over) is named by the QA, through `check` and `fit` of an acquisition; it had passed both
("RESULT: PASS", "QA verdict: good")."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
SOURCE = REPO / "tests" / "data" / "neuralrti_replay"
runner = CliRunner()


@pytest.fixture
def acq(tmp_path: Path) -> Path:
    acq = tmp_path / "acq"
    shutil.copytree(SOURCE, acq)
    return acq


def _names(acq: Path) -> list[str]:
    return [line.split()[0] for line in (acq / "dirs.lp").read_text().splitlines()[1:] if line]


def test_an_image_copied_over_another_is_named_by_check_and_fit(acq: Path, tmp_path: Path) -> None:
    names = _names(acq)
    shutil.copyfile(acq / names[0], acq / names[6])
    r = runner.invoke(app, ["check", str(acq / "dirs.lp")], terminal_width=400)
    text = " ".join(r.output.split())
    assert "Traceback" not in text, r.output
    assert f"{names[6]} is the same file as {names[0]}, byte for byte" in text, text
    assert r.exit_code == 1 and "RESULT: FAIL" in text, text
    r = runner.invoke(
        app, ["fit", str(acq / "dirs.lp"), "--out", str(tmp_path / "fit")], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    qa = json.loads((tmp_path / "fit" / "qa.json").read_text())
    assert (
        f"the same picture as {Path(names[0]).stem}, though another light lit it" in (qa["verdict"])
    ), qa["verdict"]
    assert not qa["verdict"].startswith("good"), qa["verdict"]


def test_the_acquisition_as_recorded_has_no_repeated_picture(acq: Path) -> None:
    r = runner.invoke(app, ["check", str(acq / "dirs.lp")], terminal_width=400)
    assert "the same picture as" not in r.output, r.output
