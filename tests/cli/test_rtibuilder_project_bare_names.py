"""An RTIBuilder project made as docs/guide.md §8 says (a session's ``lights.lp``, bare names,
in ``assembly-files/``; its JPEGs in ``jpeg-exports/``) is read back by every command.

Why: §10 says such a project folder is read from the one ``.lp`` in its ``assembly-files/``,
but only absolute names (what RTIBuilder writes) were looked for in ``jpeg-exports/``: the
guide's own recipe was refused by fit, run, check and bench as "18 of 18 image(s) missing in
proj/assembly-files … copy them where their names point", away from RTIBuilder's layout."""

from __future__ import annotations

import shutil
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import image_path, read_lp

ACQ = Path(__file__).resolve().parents[2] / "tests" / "data" / "neuralrti_replay"
runner = CliRunner()


def _project(tmp_path: Path) -> Path:
    proj = tmp_path / "proj"
    (proj / "jpeg-exports").mkdir(parents=True)
    (proj / "assembly-files").mkdir()
    for image in ACQ.glob("*.jpg"):
        shutil.copy2(image, proj / "jpeg-exports" / image.name)
    shutil.copy2(ACQ / "dirs.lp", proj / "assembly-files" / "proj.lp")
    return proj


def test_a_project_of_bare_names_is_fitted_run_and_checked(tmp_path: Path) -> None:
    proj = _project(tmp_path)
    r = runner.invoke(app, ["fit", str(proj), "--out", str(tmp_path / "f")])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "f" / "fit.rti").is_file()
    r = runner.invoke(app, ["run", str(proj), "--out", str(tmp_path / "s"), "--lights", "6"])
    assert r.exit_code == 0, r.output
    assert len(read_lp(tmp_path / "s" / "lights.lp")) == 6
    r = runner.invoke(app, ["check", str(proj)])
    assert r.exit_code == 0, r.output
    assert "RESULT: PASS" in r.output


def test_an_image_missing_from_the_project_is_said_missing_in_its_jpeg_exports(
    tmp_path: Path,
) -> None:
    proj = _project(tmp_path)
    (proj / "jpeg-exports" / "image09.jpg").unlink()
    r = runner.invoke(app, ["fit", str(proj), "--out", str(tmp_path / "f")])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, r.output
    assert f"1 of 18 image(s) missing in {proj / 'jpeg-exports'} (image09.jpg)" in text, text
    assert not (tmp_path / "f").exists()


def test_a_bare_name_beside_the_lp_is_still_read_there_first(tmp_path: Path) -> None:
    """The name says "beside the .lp": a file there wins over the project's export."""
    proj = _project(tmp_path)
    beside = proj / "assembly-files" / "image09.jpg"
    shutil.copy2(ACQ / "image13.jpg", beside)  # another image, to tell which was read

    assert image_path(proj / "assembly-files", "image09.jpg") == beside
    assert (
        image_path(proj / "assembly-files", "image13.jpg") == proj / "jpeg-exports" / "image13.jpg"
    )
    # a name with a folder in it is the user's path, read as written
    assert (
        image_path(proj / "assembly-files", "x/image13.jpg")
        == proj / "assembly-files" / "x" / "image13.jpg"
    )
