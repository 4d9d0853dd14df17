"""An `.lp` naming its images by another machine's absolute path (RTIBuilder, Windows:
``C:\\captures\\sub\\image01.jpg``) whose images were copied with their folder
(``ACQ/sub/image01.jpg``) is read: the name's trailing components are tried under the .lp's
folder, longest first. Only ``ACQ/image01.jpg`` had been tried, and `check` and `run` said all
18 images missing. A name that could be two different files is refused, naming both."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"
runner = CliRunner()


def _windows_acquisition(tmp_path: Path) -> Path:
    """The real neuralrti acquisition in ``acq/sub/``, its .lp in ``acq/`` naming each image
    as ``C:\\captures\\sub\\NAME``."""
    acq = tmp_path / "acq"
    (acq / "sub").mkdir(parents=True)
    lines = (ACQ / "dirs.lp").read_text().splitlines()
    out = [lines[0]]
    for line in lines[1:]:
        name, *xyz = line.split()
        shutil.copy(ACQ / name, acq / "sub" / name)
        out.append(" ".join([f"C:\\captures\\sub\\{name}", *xyz]))
    (acq / "dirs.lp").write_text("\r\n".join(out) + "\r\n")
    return acq


def test_images_in_the_subfolder_the_windows_path_names_are_checked_and_replayed(
    tmp_path: Path,
) -> None:
    acq = _windows_acquisition(tmp_path)
    r = runner.invoke(app, ["check", str(acq / "dirs.lp")])
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "RESULT: PASS" in said, said
    assert "18 listed in dirs.lp, each present in sub" in said, said

    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--lights", "4"])
    assert r.exit_code == 0, r.output
    assert len(list((out / "linear").glob("*.tif"))) == 4

    # a copy of one image also beside the .lp is the same photograph: no ambiguity
    shutil.copy(acq / "sub" / "image01.jpg", acq / "image01.jpg")
    r = runner.invoke(app, ["check", str(acq / "dirs.lp")])
    assert r.exit_code == 0 and "RESULT: PASS" in r.output, r.output


def test_a_name_that_could_be_two_different_files_is_refused_naming_both(
    tmp_path: Path,
) -> None:
    acq = _windows_acquisition(tmp_path)
    shutil.copy(acq / "sub" / "image05.jpg", acq / "image01.jpg")  # another light's image
    for args in (
        ["check", str(acq / "dirs.lp")],
        ["run", str(acq / "dirs.lp"), "--out", str(tmp_path / "s")],
    ):
        r = runner.invoke(app, args)
        said = " ".join(r.output.split())
        assert r.exit_code == 2, said
        assert "'C:\\captures\\sub\\image01.jpg' could be sub/image01.jpg, image01.jpg" in said
        assert "write the name relative to the .lp's folder" in said, said
        assert "Traceback" not in said and "RESULT: PASS" not in said
    assert not (tmp_path / "s" / "linear").exists()


def test_an_image_in_none_of_the_folders_tried_is_said_missing_with_where_it_was_looked_for(
    tmp_path: Path,
) -> None:
    acq = _windows_acquisition(tmp_path)
    (acq / "sub" / "image09.jpg").unlink()
    r = runner.invoke(app, ["check", str(acq / "dirs.lp")])
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "1 of 18 image(s) missing" in said, said
    assert "trailing folders and file name under the .lp's folder" in said, said


@pytest.mark.parametrize("prefix,folder", [("C:", "."), ("C:sub/", "sub"), ("C:sub\\", "sub")])
def test_drive_relative_names_are_looked_for_under_the_lp_folder(
    tmp_path: Path, prefix: str, folder: str
) -> None:
    """A drive-relative Windows name (``C:image01.jpg``: the current folder of drive C:) had
    been read, without a ``\\``, as one POSIX component ``C:image01.jpg`` and said missing
    although ``image01.jpg`` was beside the .lp; with ``/`` its folder was never tried."""
    acq = tmp_path / "acq"
    (acq / folder).mkdir(parents=True, exist_ok=True)
    lines = (ACQ / "dirs.lp").read_text().splitlines()
    out = [lines[0]]
    for line in lines[1:]:
        name, *xyz = line.split()
        shutil.copy(ACQ / name, acq / folder / name)
        out.append(" ".join([f"{prefix}{name}", *xyz]))
    (acq / "dirs.lp").write_text("\n".join(out) + "\n")
    r = runner.invoke(app, ["check", str(acq / "dirs.lp")])
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "RESULT: PASS" in said, said
    assert "18 listed in dirs.lp" in said, said
