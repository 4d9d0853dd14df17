"""An acquisition whose images do not change with their light is not "good".

Every image the same picture (the dome's LEDs never fired while the room light was on, or one
frame saved under every light's name) had been fitted and told "QA verdict: good": a PTM
explains a constant image exactly, so no per-image check, each comparing an image with the fit,
found anything, and the normal map was a least-squares answer to lights that changed nothing.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, read_lp, write_lp
from rti_rig.reconstruct.synthetic import render, sphere_normals

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
SAID = "the images do not change with their light"


def _fit(tmp_path: Path, entries: list[LpEntry]) -> str:
    lp = tmp_path / "dirs.lp"
    write_lp(lp, entries)
    r = CliRunner().invoke(app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--no-hsh"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "Traceback" not in said, said
    return said


@pytest.mark.parametrize("frame", ["one photo", "flat grey"])
def test_the_same_frame_under_every_light_is_called_so_once(tmp_path: Path, frame: str) -> None:
    entries = read_lp(ACQ)
    img = (
        cv2.resize(cv2.imread(str(ACQ.parent / entries[1].name)), (64, 64))  # 16° up: unclipped
        if frame == "one photo"
        else np.full((64, 64, 3), 118, np.uint8)
    )
    for e in entries:
        cv2.imwrite(str(tmp_path / e.name), img)
    said = _fit(tmp_path, entries)
    assert "QA verdict: good" not in said, said
    # one fault of the whole session, said once for the run of images, with what to do
    assert said.count(SAID) == 1, said
    first, last = Path(entries[0].name).stem, Path(entries[-1].name).stem
    assert f"{first} ... {last} ({len(entries)} images: {SAID}" in said
    # an imported acquisition: told what it is, not to reshoot (it had been "then reshoot")
    assert "then reshoot" not in said
    assert "saved under every name); so they are in the acquisition" in said


def test_images_that_follow_their_light_are_not_called_unchanging(tmp_path: Path) -> None:
    """The same lights, a matte sphere rendered under each: its shading changes."""
    entries = read_lp(ACQ)
    normals, _ = sphere_normals(64, 64)
    lights = np.array([e.direction for e in entries])
    for e, img in zip(entries, render(normals, 0.7, lights), strict=True):
        grey = np.clip(img * 255.0, 0, 255).astype(np.uint8)
        cv2.imwrite(str(tmp_path / e.name), cv2.merge([grey, grey, grey]))
    said = _fit(tmp_path, entries)
    assert "QA verdict" in said and SAID not in said, said


def test_a_ring_of_lights_over_a_level_object_may_give_one_picture(tmp_path: Path) -> None:
    """Lights at one elevation light a level matte object alike: identical images are what
    such a session gives, not a fault."""
    az = np.radians(np.arange(0.0, 360.0, 30.0))
    el = np.radians(40.0)
    entries = [
        LpEntry(f"ring_{i:02d}.png", (np.cos(el) * np.cos(a), np.cos(el) * np.sin(a), np.sin(el)))
        for i, a in enumerate(az)
    ]
    rng = np.random.default_rng(3)
    texture = rng.integers(60, 180, (64, 64), dtype=np.uint8)  # printed, level, matte
    for e in entries:
        cv2.imwrite(str(tmp_path / e.name), texture)
    said = _fit(tmp_path, entries)
    assert SAID not in said, said


def test_no_image_is_judged_against_a_fit_of_unchanging_images(
    tmp_path_factory: pytest.TempPathFactory,
) -> None:
    """The shipped dome's first image saved under every light's name (a camera that ignores
    the lights): the verdict had said "image_001 (3.0× brighter than the other images
    predict)" and "on a near-flat object" beside it, claims of a fit no such images allow.
    The one true thing is said, and nothing of any image against the fit."""
    import shutil

    from conftest import dome_session

    root = tmp_path_factory.mktemp("same")
    session = dome_session(root, "relief", 128, 12)
    acq = root / "acq"
    acq.mkdir()
    shutil.copy(session / "lights.lp", acq / "lights.lp")
    for image in sorted(session.glob("image_*.jpg")):
        shutil.copy(session / "image_001.jpg", acq / image.name)
    r = CliRunner().invoke(app, ["fit", str(acq / "lights.lp"), "--out", str(root / "f")])
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "Traceback" not in said, said
    assert f"QA verdict: reshoot: image_001 ... image_012 (12 images: {SAID}" in said, said
    assert "brighter than" not in said and "dimmer than" not in said, said
    assert "near-flat object" not in said and said.count(SAID) == 1
    assert "light directions not checked: with every image alike, none tells its light" in said
