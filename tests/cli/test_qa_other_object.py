"""One image of another object in an acquisition is named as that, not as a dim light.

Found by swapping images between sessions of the shipped simulated dome: a painting's picture
in place of image_020 of the relief's 48 (an acquisition copied by hand, its record left
behind) was called "good", and most other swaps "misfired or dim light", a cause that sends a
conservator to the dome's LEDs. The QA now compares each image's edges with the session's
(rti_rig.reconstruct.qa_other_object) and names the picture that shares none of them.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import dome_session, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.reconstruct.qa_other_object import (
    MAX_SHARE,
    MIN_JUDGED,
    OTHER_OBJECT,
    OTHER_OBJECT_SHARE,
    other_object_images,
)

runner = CliRunner()


def _copied(session: Path, dst: Path) -> Path:
    """``session``'s JPEGs and lights.lp alone: an acquisition copied without its record."""
    dst.mkdir()
    shutil.copy(session / "lights.lp", dst)
    for jpg in session.glob("image_*.jpg"):
        shutil.copy(jpg, dst / jpg.name)
    return dst


def _qa(folder: Path, out: Path) -> dict:  # type: ignore[type-arg]
    r = runner.invoke(app, ["fit", str(folder), "--out", str(out), "--no-ptm", "--no-hsh"])
    assert r.exit_code == 0, r.output
    assert "QA verdict:" in said(r), said(r)
    return json.loads((out / "qa.json").read_text())


@pytest.fixture(scope="module")
def painting(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A session of the shipped dome's frame size on the painting (12 lights)."""
    return dome_session(tmp_path_factory.mktemp("painting"), "painting", 512, 12)


def test_a_painting_in_the_reliefs_acquisition_is_named(
    dome_relief: Path, painting: Path, tmp_path: Path
) -> None:
    folder = _copied(dome_relief, tmp_path / "acq")
    shutil.copy(painting / "image_008.jpg", folder / "image_020.jpg")
    qa = _qa(folder, tmp_path / "f")
    assert qa["reshoot"] == ["image_020"], qa["verdict"]
    check = next(c for c in qa["images"] if c["name"] == "image_020")
    # its own cause alone: not a dim light, a wrong light or a brighter image besides
    assert len(check["problems"]) == 1, check["problems"]
    assert check["problems"][0].startswith(f"{OTHER_OBJECT}: its edges match"), check["problems"]
    assert f"image_020 ({OTHER_OBJECT}" in qa["verdict"], qa["verdict"]
    assert qa["thresholds"]["other_object_share"] == OTHER_OBJECT_SHARE


def test_the_acquisition_as_shot_names_no_image(dome_relief: Path, tmp_path: Path) -> None:
    qa = _qa(_copied(dome_relief, tmp_path / "acq"), tmp_path / "f")
    assert qa["reshoot"] == [], qa["verdict"]
    assert OTHER_OBJECT not in qa["verdict"]


def test_the_session_itself_names_no_image(painting: Path, tmp_path: Path) -> None:
    """The painting's own session, with its record (linear TIFFs read), 12 lights."""
    qa = _qa(painting, tmp_path / "f")
    assert not any(p.startswith(OTHER_OBJECT) for c in qa["images"] for p in c["problems"]), qa[
        "verdict"
    ]


def test_only_a_lit_image_of_a_session_with_edges_is_judged() -> None:
    corr = np.full(12, 0.8)
    corr[5] = 0.1
    levels = np.ones(12)
    assert set(other_object_images(corr, levels)) == {5}
    # mostly in shadow (a light behind a tilted plane): few edges to share, not judged
    dim = levels.copy()
    dim[5] = 0.3
    assert other_object_images(corr, dim) == {}
    # a featureless plate: no typical correlation to compare with
    assert other_object_images(np.where(corr > 0.5, 0.15, 0.01), levels) == {}
    # an image ECC could not register reads 0 (nothing in common): named
    corr[5] = 0.0
    assert set(other_object_images(corr, levels)) == {5}
    # a featureless one (nan) is not judged
    corr[5] = np.nan
    assert other_object_images(corr, levels) == {}
    # a run of MIN_RUN in capture order is the object moved past what registration follows,
    # not stray files (an unjudged image between does not break the run)
    run = np.full(40, 0.8)
    run[[10, 11, 13]] = 0.0
    run[12] = np.nan
    assert other_object_images(run, np.ones(40)) == {}
    run[13] = 0.8
    assert set(other_object_images(run, np.ones(40))) == {10, 11}
    # ... and so are more than MAX_SHARE of the images, scattered
    scattered = np.full(40, 0.8)
    scattered[::8] = 0.0
    assert other_object_images(scattered, np.ones(40)) == {}
    assert MAX_SHARE * 40 < 5
    # too few judged images to know what is typical
    few = np.full(MIN_JUDGED - 1, 0.8)
    few[0] = 0.0
    assert other_object_images(few, np.ones(few.size)) == {}


def test_it_stands_whatever_the_lights() -> None:
    """Found from edges alone, with no fit: under lights likely wrong it is still named."""
    from rti_rig.reconstruct.qa import lights_independent
    from rti_rig.reconstruct.qa_other_object import other_object_problem

    assert lights_independent(other_object_problem(0.1, 0.8))
