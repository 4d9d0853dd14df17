"""`rti-rig check ACQ/dirs.lp` says an acquisition's bad images as a failed check (each
problem named, RESULT: FAIL, exit 1), as `check --help` and docs/guide.md describe; exit 2
stays for input that is not an acquisition at all. An image deleted or resized had been said
as a usage error ("error: … 1 of 18 image(s) missing …", exit 2), and only the first problem."""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
from typer.testing import CliRunner

from rti_rig.cli import app

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"
runner = CliRunner()


def test_a_deleted_and_a_resized_image_fail_the_check_each_named(tmp_path: Path) -> None:
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    (acq / "image09.jpg").unlink()
    first = cv2.imread(str(acq / "image01.jpg"))
    height, width = first.shape[:2]
    assert cv2.imwrite(str(acq / "image05.jpg"), cv2.resize(first, (width - 2, height)))
    r = runner.invoke(app, ["check", str(acq / "dirs.lp")])
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert "1 of 18 image(s) missing" in said and "(image09.jpg)" in said, said
    assert f"image01.jpg is {width}x{height} but image05.jpg is {width - 2}x{height}" in said
    assert said.endswith("RESULT: FAIL") and "error:" not in said and "Traceback" not in said


def test_input_that_is_not_an_acquisition_stays_a_usage_error(tmp_path: Path) -> None:
    text = tmp_path / "notes.txt"
    text.write_text("not a rig config\n")
    broken = tmp_path / "broken.lp"
    broken.write_text("3\nimage01.jpg 0.1 0.2\n")  # a line with two of its three numbers
    for path in (text, broken):
        r = runner.invoke(app, ["check", str(path)])
        said = " ".join(r.output.split())
        assert r.exit_code == 2, said
        assert "RESULT" not in said and "Traceback" not in said


def test_intensity_on_a_replay_is_refused_by_name() -> None:
    """A replay's "LEDs" are recorded images: ``--intensity`` had passed without a word, as if
    the level had been used. It is refused as ``--auto-exposure`` is (exit 2, drop it)."""
    r = runner.invoke(app, ["check", str(ACQ / "dirs.lp"), "--intensity", "0.5"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "--intensity 0.5 cannot be used on a replayed acquisition" in said, said
    assert "drop --intensity" in said and "RESULT" not in said and "Traceback" not in said
    r = runner.invoke(app, ["check", str(ACQ / "dirs.lp")])
    assert r.exit_code == 0 and "RESULT: PASS" in r.output, r.output
