"""An image beside an imported acquisition's ``.lp`` that the ``.lp`` does not list is named.

Found by a QA sweep: a real acquisition (NeuralRTI's, ``tests/data/neuralrti_replay``) whose
``dirs.lp`` had lost image33's line, image33.jpg still beside it, was fitted without it and
said nothing of it; relight's folder mode, which takes every JPEG beside the ``.lp`` with
its lines in name order, would be put out of step. The QA's own advice for an imported acquisition
("leave the images named out of the .lp") made such a folder, and now says to move the
files out too.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import REPO, qa_of

REAL = REPO / "tests" / "data" / "neuralrti_replay"


def _without_line(tmp_path: Path, image: str) -> Path:
    acq = tmp_path / "acq"
    shutil.copytree(REAL, acq)
    lp = acq / "dirs.lp"
    lines = lp.read_text(encoding="utf-8").splitlines()
    kept = [line for line in lines[1:] if line.strip() and not line.startswith(image)]
    assert len(kept) == int(lines[0]) - 1
    lp.write_text(f"{len(kept)}\n" + "\n".join(kept) + "\n", encoding="utf-8")
    return acq


@pytest.mark.e2e
def test_a_jpeg_whose_line_was_lost_is_named_with_what_to_do(tmp_path: Path) -> None:
    acq = _without_line(tmp_path, "image33.jpg")
    (acq / "._image01.jpg").write_bytes(b"\x00\x05\x16\x07")  # what macOS leaves on a card

    text, qa = qa_of(acq, tmp_path / "fit")

    assert (
        "image33.jpg, beside dirs.lp, is not listed in it, so not fitted (left out on purpose, "
        "or its line lost?); relight's folder mode takes every JPEG beside the .lp"
    ) in text, text
    assert "add its line to dirs.lp with its light, or move it out of the folder" in text
    assert "._image01" not in text, text
    assert len(qa["images"]) == 17 and any("image33.jpg" in c for c in qa["caveats"])
    # the imported acquisition's own advice no longer makes such a folder
    assert "out of the .lp and move their files out of its folder" in text, text


@pytest.mark.e2e
def test_an_acquisition_listing_every_image_beside_it_says_nothing_of_it(tmp_path: Path) -> None:
    text, _ = qa_of(REAL / "dirs.lp", tmp_path / "fit")

    assert "not listed in it" not in text, text


@pytest.mark.e2e
def test_images_another_lp_beside_it_lists_are_left_to_it(tmp_path: Path) -> None:
    """A subset's .lp beside the whole one: the images it leaves out are the whole one's, and
    moving them out of the folder (the advice) would break that one."""
    acq = tmp_path / "acq"
    shutil.copytree(REAL, acq)
    lines = (acq / "dirs.lp").read_text(encoding="utf-8").splitlines()
    subset = [line for line in lines[1:] if line.strip()][:10]
    (acq / "subset.lp").write_text(f"{len(subset)}\n" + "\n".join(subset) + "\n")

    text, qa = qa_of(acq / "subset.lp", tmp_path / "fit")

    assert len(qa["images"]) == 10
    assert "not listed in it" not in text, text
