"""An imported acquisition (an ``.lp`` and its JPEGs, no rti-rig session record) is not told to
reshoot, through the front door.

Found by an audit: ``rti-rig fit`` of a published archive acquisition (NeuralRTI's example, a
gilded icon) said "QA verdict: reshoot: image01 (saturated ...; reshoot with less exposure)",
advice for an object nobody can put back under that dome. The problems are still named, as
the acquisition's, with what a user can do about them.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from conftest import qa_of

from rti_rig.core.image_files import read_linear_tiff
from rti_rig.core.lp_format import LpEntry, read_lp, write_lp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

SATURATED = 4  # 0-based: image_005, six times over its exposure


def _srgb8(linear: np.ndarray) -> np.ndarray:
    v = np.clip(linear, 0.0, 1.0)
    s = np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)
    return np.round(s * 255.0).astype(np.uint8)


@pytest.fixture(scope="module")
def shot(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A session laid out as rti-rig writes one (lights.lp, linear TIFFs), one image clipped."""
    root = tmp_path_factory.mktemp("imported")
    session, _, _ = make_session(root / "session", size=(64, 80), saturate=SATURATED)
    return session


def as_imported(session: Path, acq: Path) -> Path:
    """A session's images as an archive acquisition in ``acq``: JPEGs and a dirs.lp, nothing
    else (its ``dirs.lp``)."""
    acq.mkdir()
    entries = []
    for k, e in enumerate(read_lp(session / "lights.lp")):
        px = read_linear_tiff(session / "linear" / f"{Path(e.name).stem}.tif") / 65535.0
        name = f"image{k + 1:02d}.jpg"
        cv2.imwrite(str(acq / name), _srgb8(px), [cv2.IMWRITE_JPEG_QUALITY, 95])
        entries.append(LpEntry(name, e.direction))
    write_lp(acq / "dirs.lp", entries)
    return acq / "dirs.lp"


@pytest.fixture(scope="module")
def imported(shot: Path) -> Path:
    """The same images as an archive acquisition: JPEGs and a dirs.lp, nothing else."""
    return as_imported(shot, shot.parent / "acquisition")


def test_an_imported_acquisition_is_told_what_it_can_do(imported: Path, tmp_path: Path) -> None:
    text, qa = qa_of(imported, tmp_path / "fit")
    assert "QA verdict: flawed: image05 (saturated" in text, text
    assert "reshoot with less exposure" not in text
    assert "QA verdict: reshoot" not in text
    assert "an imported acquisition" in text and "reshoot only if the object can be" in text
    assert qa["good"] is False  # the problem is still the acquisition's: not a clean verdict
    problems = qa["images"][SATURATED]["problems"]
    assert any("clipped in the acquisition" in p for p in problems), problems
    assert not any("reshoot" in p for p in problems), problems


def test_a_session_of_this_rig_is_still_told_to_reshoot(shot: Path, tmp_path: Path) -> None:
    """The same clipped image in a session's layout (rti-rig wrote it; its manifest may be
    lost, the object may still be under the dome) keeps the advice to reshoot it."""
    session = tmp_path / "session"
    shutil.copytree(shot, session)
    text, _ = qa_of(session, tmp_path / "fit")
    assert "QA verdict: reshoot: image_005 (saturated" in text, text
    assert "reshoot with less exposure" in text
    assert "an imported acquisition" not in text


def test_every_reshoot_advice_has_words_where_none_can_be_followed() -> None:
    """One table per kind of session that cannot reshoot, covering every advice to reshoot:
    a phrase added to REDO_ADVICE without its words here would still tell an imported
    acquisition to reshoot (the flat frame's "reshoot it" and the unchanging images' "then
    reshoot" had been)."""
    from rti_rig.app.usecases.session_integrity import (
        ADAPTIVE_ADVICE,
        IMPORTED_ADVICE,
        REPLAYED_ADVICE,
    )
    from rti_rig.reconstruct.qa import LESS_EXPOSURE, REDO_ADVICE

    assert set(IMPORTED_ADVICE) == set(REDO_ADVICE)
    assert not any("reshoot" in v for v in IMPORTED_ADVICE.values())
    for table in (REPLAYED_ADVICE, ADAPTIVE_ADVICE):  # their clipped image's words name more
        assert set(table) | {LESS_EXPOSURE} == set(REDO_ADVICE)


def test_an_imported_acquisition_moved_part_way_is_not_told_to_reshoot(tmp_path: Path) -> None:
    """A move part-way through, found in an imported acquisition, is named as the
    acquisition's with what can be done about it (it had been told "reshoot the whole
    session"); a session of this rig moved the same way keeps that advice
    (test_qa_move_part_way)."""
    moved, _, _ = make_session(tmp_path / "moved", size=(96, 112), move=(18, 2, 1))
    text, qa = qa_of(as_imported(moved, tmp_path / "acquisition"), tmp_path / "fit")
    assert "QA verdict: flawed: image19 ... image36 (18 images: object or camera moved" in text
    assert "reshoot the whole session" not in text and "reshooting from" not in text, text
    assert "align the images from the move on to the earlier ones" in text, text
    assert qa["reshoot"] == [f"image{i:02d}" for i in range(19, 37)], qa["verdict"]
    for c in qa["images"]:
        assert not any("reshoot" in p for p in c["problems"]), c["problems"]


def _record_lost(shot: Path, dst: Path) -> Path:
    """``shot`` as a session folder is left when its manifest, journal and linear/ are lost:
    its JPEGs (made from the linear TIFFs, as a run writes them) and its lights.lp."""
    shutil.copytree(shot, dst)
    for e in read_lp(dst / "lights.lp"):
        px = read_linear_tiff(dst / "linear" / f"{Path(e.name).stem}.tif") / 65535.0
        cv2.imwrite(str(dst / e.name), _srgb8(px), [cv2.IMWRITE_JPEG_QUALITY, 95])
    shutil.rmtree(dst / "linear")
    return dst


def test_a_session_that_lost_its_record_is_not_called_imported(shot: Path, tmp_path: Path) -> None:
    """Manifest, journal and linear/ lost, lights.lp and rti-rig's image names left: said to be
    a session whose record is missing (it had been "an imported acquisition", its clipped
    image "clipped in the acquisition"), with the advice to reshoot, as the object may still be
    under the dome."""
    text, _ = qa_of(_record_lost(shot, tmp_path / "s"), tmp_path / "fit")
    assert "QA verdict: reshoot: image_005 (saturated" in text, text
    assert "reshoot with less exposure" in text
    assert "an imported acquisition" not in text, text
    assert "the session record is missing" in text, text
    assert "lights.lp lists image_001.jpg … image_036.jpg" in text, text


def test_a_records_folder_left_is_a_trace_too(imported: Path, tmp_path: Path) -> None:
    """Images renamed, yet the step records rti-rig keeps beside them still there."""
    acq = tmp_path / "acquisition"
    shutil.copytree(imported.parent, acq)
    (acq / "records").mkdir()
    (acq / "records" / "image_001.json").write_text("{}", encoding="utf-8")
    text, _ = qa_of(acq / imported.name, tmp_path / "fit")
    assert "the session record is missing" in text and "a records/ folder" in text, text
    assert "an imported acquisition" not in text, text


def _shuffled(session: Path) -> Path:
    """``session`` with its lights.lp's directions shuffled among its images (seed 1)."""
    entries = read_lp(session / "lights.lp")
    order = np.random.default_rng(1).permutation(len(entries))
    write_lp(
        session / "lights.lp",
        [LpEntry(e.name, entries[k].direction) for e, k in zip(entries, order, strict=True)],
    )
    return session


def test_an_imported_acquisition_with_a_shuffled_lp_is_told_of_no_images_named(
    tmp_path: Path,
) -> None:
    """Its lights likely wrong, the verdict names no image for what its lights explain, yet
    the imported acquisition's note ("the problems named are its images' … leave the images
    named out of the .lp") was said beside it; its images' problems in qa.json still carry no
    advice to reshoot."""
    session, _, _ = make_session(tmp_path / "s", size=(64, 80))
    lp = as_imported(_shuffled(session), tmp_path / "acquisition")
    text, qa = qa_of(lp, tmp_path / "fit")
    assert "QA verdict: lights likely wrong: " in text, text
    assert qa["reshoot"] == [], qa["verdict"]
    assert "an imported acquisition" not in text and "images named" not in text, text
    assert any(c["problems"] for c in qa["images"]), qa["verdict"]  # checked, not named
    for c in qa["images"]:
        assert not any("reshoot" in p for p in c["problems"]), c["problems"]


def test_a_clipped_image_of_a_shuffled_imported_acquisition_keeps_the_note(
    shot: Path, tmp_path: Path
) -> None:
    """Whatever the lights, a clipped image is named: the note and its word stay."""
    session = tmp_path / "s"
    shutil.copytree(shot, session)
    lp = as_imported(_shuffled(session), tmp_path / "acquisition")
    text, qa = qa_of(lp, tmp_path / "fit")
    assert "; flawed whatever the lights: image05 (saturated" in text, text
    assert "an imported acquisition" in text, text
    assert qa["reshoot"] == ["image05"], qa["verdict"]
