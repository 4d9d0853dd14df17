"""A fit says when its lights repeat a direction, whatever the model.

A plan or a dome's calibration that repeats a light is refused, saying so; a fit of 7 images
of which 3 share one direction said nothing of it with ``--model ptm`` ("these lights cannot
separate its 6 terms" only), leaving the user to find that 7 images gave 5 directions.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, read_lp, write_lp

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"


def _seven(folder: Path, repeat: tuple[int, ...]) -> Path:
    """The replay's first 7 images, those of ``repeat`` lit from the first one's direction."""
    folder.mkdir()
    entries = read_lp(ACQ)[:7]
    for e in entries:
        shutil.copy(ACQ.parent / e.name, folder / e.name)
    first = entries[0].direction
    lp = folder / "dirs.lp"
    write_lp(
        lp, [LpEntry(e.name, first if k in repeat else e.direction) for k, e in enumerate(entries)]
    )
    return lp


@pytest.mark.parametrize("model", ["ptm", "auto"])
def test_three_images_of_one_direction_are_said(tmp_path: Path, model: str) -> None:
    lp = _seven(tmp_path / "acq", (0, 3, 5))
    r = CliRunner().invoke(
        app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--model", model, "--no-qa"]
    )
    text = said(r)
    assert r.exit_code == 0, text
    assert "lights repeated: image01, image13 and image21 share one direction" in text, text
    assert "the 7 images give 5 distinct lights" in text
    assert "too few distinct for --model ptm (6 terms)" in text


def test_distinct_lights_are_not_said_to_repeat(tmp_path: Path) -> None:
    lp = _seven(tmp_path / "acq", ())
    r = CliRunner().invoke(
        app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--model", "ptm", "--no-qa"]
    )
    assert r.exit_code == 0, said(r)
    assert "repeated" not in said(r)


@pytest.mark.parametrize(
    ("args", "ptm_named"),
    [
        (("--model", "auto", "--no-ptm"), False),
        (("--model", "hsh1", "--no-ptm"), False),
        (("--model", "ptm", "--no-ptm"), True),  # the model itself: fitted, not written
        (("--model", "hsh1"), True),  # fit.ptm written beside fit.rti
    ],
)
def test_the_repeat_names_a_ptm_only_where_one_is_fitted(
    tmp_path: Path, args: tuple[str, ...], ptm_named: bool
) -> None:
    """With --no-ptm the note had said "too few distinct for --model ptm (6 terms), fitted
    ridge-regularised and not to be trusted" of a fit that fitted and wrote no PTM."""
    lp = _seven(tmp_path / "acq", (0, 3, 5))
    r = CliRunner().invoke(app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--no-qa", *args])
    text = said(r)
    assert r.exit_code == 0, text
    assert "lights repeated: image01, image13 and image21 share one direction" in text, text
    assert ("--model ptm (6 terms)" in text) == ptm_named, text
    assert (tmp_path / "f" / "fit.ptm").exists() == ("--no-ptm" not in args)


def _twelve(folder: Path) -> Path:
    """The replay's first 12 images, 5 of them lit from the first one's direction: 8
    distinct lights, too few for hsh2's 9 terms, enough for hsh1 and a PTM."""
    folder.mkdir()
    entries = read_lp(ACQ)[:12]
    for e in entries:
        shutil.copy(ACQ.parent / e.name, folder / e.name)
    first = entries[0].direction
    lp = folder / "dirs.lp"
    repeat = (0, 2, 4, 6, 8)
    write_lp(
        lp, [LpEntry(e.name, first if k in repeat else e.direction) for k, e in enumerate(entries)]
    )
    return lp


@pytest.mark.parametrize(
    ("args", "hsh2_named"),
    [
        (("--model", "hsh2"), True),
        (("--model", "ptm", "--hsh-order", "1"), False),
        (("--model", "ptm", "--no-hsh"), False),
    ],
)
def test_the_repeat_names_an_hsh_only_where_one_is_fitted(
    tmp_path: Path, args: tuple[str, ...], hsh2_named: bool
) -> None:
    """The note had named hsh2 as "fitted ridge-regularised and not to be trusted" of fits
    whose fit.rti was hsh1, or that wrote no fit.rti."""
    lp = _twelve(tmp_path / "acq")
    r = CliRunner().invoke(app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--no-qa", *args])
    text = said(r)
    assert r.exit_code == 0, text
    assert "the 12 images give 8 distinct lights" in text, text
    assert ("--model hsh2 (9 terms)" in text) == hsh2_named, text
    assert ("fit.rti: hsh2" in text) == hsh2_named, text
