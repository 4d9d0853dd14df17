"""`rti-rig plan PREVIEW --rig ACQ/dirs.lp` reads the preview's light from the .lp line that names
it but for upper/lower case, and says so with both names.

A preview ``image09.JPG`` against the line ``image09.jpg ...`` (one file on Windows and macOS,
where the .lp was written; a camera's own upper-case name on a Linux disk) had been told the .lp
"does not list it", and the plan was made from a light estimated from its shading, here 35°
from the light the .lp records for it. A name listed exactly still wins; two lines naming it
but for case are refused, naming both, since which of them lit it is not known.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.core.lp_format import read_lp

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"
runner = CliRunner()


def _acquisition(tmp_path: Path) -> Path:
    """The replay acquisition, its third image (``image09.jpg`` in dirs.lp) on disk as
    ``image09.JPG``."""
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    (acq / "image09.jpg").rename(acq / "image09.JPG")
    return acq


def _light_said(acq: Path, name: str) -> str:
    """The light dirs.lp records for ``name``, as the plan prints it."""
    (entry,) = [e for e in read_lp(acq / "dirs.lp") if e.name == name]
    az, el = (float(v) for v in az_el_from_direction(np.asarray(entry.direction)))
    return f"az {az:.1f}°, el {el:.1f}°"


def _rename_line(acq: Path, old: str, new: str) -> None:
    """dirs.lp with the image name of one line changed (its light kept)."""
    lp = acq / "dirs.lp"
    lines = lp.read_text().splitlines()
    (k,) = [k for k, line in enumerate(lines) if line.split()[0] == old]
    lines[k] = lines[k].replace(old, new, 1)
    lp.write_text("\n".join(lines) + "\n")


def _plan(acq: Path, preview: str, *extra: str):  # type: ignore[no-untyped-def]
    out = acq.parent / "plan.lp"
    args = ["plan", str(acq / preview), "--rig", str(acq / "dirs.lp"), "--lights", "6"]
    return runner.invoke(app, [*args, "--out", str(out), "--force", *extra])


def _ignores_case(acq: Path) -> bool:
    """Whether this file system finds ``image09.JPG`` as ``image09.jpg`` (macOS, Windows)."""
    return (acq / "image09.jpg").exists()


def test_a_preview_named_but_for_case_plans_from_the_light_recorded_for_it(
    tmp_path: Path,
) -> None:
    acq = _acquisition(tmp_path)
    recorded = _light_said(acq, "image09.jpg")
    r = _plan(acq, "image09.JPG")
    text = said(r)
    assert r.exit_code == 0, text
    assert (
        f"preview light {recorded} (recorded by dirs.lp for image09.jpg, light 3 on line 4, the "
        "preview image09.JPG but for upper/lower case: " in text
    ), text
    if _ignores_case(acq):
        why = "one file here, this system ignoring the case of file names as Windows and macOS do)"
    else:
        why = (
            "read as one file, as Windows and macOS read it; this system tells the two apart, so "
            "rename the file or correct the name in the .lp)"
        )
    assert why in text, text
    assert "estimated" not in text and "does not list it" not in text, text
    assert "Traceback" not in text


def test_a_light_given_is_compared_with_the_light_recorded_for_the_case_twin(
    tmp_path: Path,
) -> None:
    acq = _acquisition(tmp_path)
    recorded = _light_said(acq, "image09.jpg")
    r = _plan(acq, "image09.JPG", "--preview-light", "10,40")
    text = said(r)
    assert r.exit_code == 0, text
    assert (
        "from the light recorded by dirs.lp for image09.jpg, light 3 on line 4, the preview "
        f"image09.JPG but for upper/lower case ({recorded}): the plan used the light given; leave "
        "--preview-light out to plan with the recorded one" in text
    ), text


def test_a_name_listed_exactly_wins_over_its_case_twin(tmp_path: Path) -> None:
    """dirs.lp lists both image09.jpg and image09.JPG: the preview image09.JPG is the second."""
    acq = _acquisition(tmp_path)
    _rename_line(acq, "image13.jpg", "image09.JPG")
    r = _plan(acq, "image09.JPG")
    text = said(r)
    assert r.exit_code == 0, text
    assert f"preview light {_light_said(acq, 'image09.JPG')} (recorded by dirs.lp)" in text, text
    assert "upper/lower case" not in text, text


def test_two_lines_naming_the_preview_but_for_case_are_refused_naming_both(
    tmp_path: Path,
) -> None:
    acq = _acquisition(tmp_path)
    _rename_line(acq, "image13.jpg", "IMAGE09.jpg")
    # a header comment: the lines to correct are no longer the lights' numbers plus one
    lp = acq / "dirs.lp"
    lp.write_text("# dome A, 2026\n" + lp.read_text())
    r = _plan(acq, "image09.JPG")
    text = said(r)
    assert r.exit_code == 2, text
    assert (
        f"{acq / 'dirs.lp'}: lights 3 (line 5: image09.jpg) and 4 (line 6: IMAGE09.jpg) each "
        "name the preview "
        "image09.JPG but for upper/lower case (one file on Windows and macOS, which ignore the "
        "case of file names), so which light lit it is not known: correct the names in the "
        ".lp, or give the light with --preview-light AZ,EL" in text
    ), text
    assert "Traceback" not in text
    # the light given stands in for the records, as the refusal says
    r = _plan(acq, "image09.JPG", "--preview-light", "10,40")
    assert r.exit_code == 0, said(r)
    assert "(given)" in said(r), said(r)


def test_a_case_twin_that_is_another_file_here_is_not_read_but_named(tmp_path: Path) -> None:
    """Where this system tells the names apart and both files are there, the line names the
    other file: the preview's light is not taken from it, and the user is told why."""
    acq = _acquisition(tmp_path)
    if _ignores_case(acq):
        pytest.skip("this file system ignores the case of file names: one file, not two")
    shutil.copy(acq / "image01.jpg", acq / "image09.jpg")
    r = _plan(acq, "image09.JPG")
    text = said(r)
    assert r.exit_code == 0, text
    assert (
        "as dirs.lp (--rig) does not list it (its light 3 on line 4, image09.jpg, differs only in "
        "upper/lower case from image09.JPG and is another file on this system, which tells the "
        "two names apart)" in text
    ), text
    assert "recorded by" not in text, text
