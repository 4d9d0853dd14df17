"""One flat frame among lit images is named by the QA.

A frame of one grey level (a frame from another source, a covered lens, a camera that sent a
blank buffer) among images of the object was judged "good" at a level near its mates' (the
simulated tablet, the real replay's image29 at its own median), and "too bright for its light"
above it: the per-image checks compare it with a fit it matches on average.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np
from conftest import qa_of

from rti_rig.core.lp_format import LpEntry, read_lp, write_lp

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
FLAT = "a flat frame: no picture of the object"


def _replay(folder: Path, flat: str | None) -> Path:
    """The real replay acquisition, ``flat`` (an image name) made one grey level: its median."""
    folder.mkdir()
    entries = read_lp(ACQ)
    for e in entries:
        img = cv2.imread(str(ACQ.parent / e.name))
        if e.name == flat:
            img = np.full_like(img, int(np.median(img)))
        cv2.imwrite(str(folder / e.name), img)
    write_lp(folder / "dirs.lp", entries)
    return folder / "dirs.lp"


def test_a_flat_frame_in_a_real_acquisition_is_named(tmp_path: Path) -> None:
    said, qa = qa_of(_replay(tmp_path / "acq", "image29.jpg"), tmp_path / "f")
    assert f"image29 ({FLAT} (one level across the frame" in said, said
    # an imported acquisition (an .lp and its JPEGs): nobody can reshoot it, and it is not told
    # to (it had been: "...; reshoot it")
    assert "reshoot it" not in said and "camera fault; so it is in the acquisition" in said
    named = [c["name"] for c in qa["images"] if any(FLAT in p for p in c["problems"])]
    assert named == ["image29"], named


def test_the_real_acquisition_itself_has_no_flat_frame(tmp_path: Path) -> None:
    said, _ = qa_of(_replay(tmp_path / "acq", None), tmp_path / "f")
    assert "QA verdict" in said
    assert "flat frame" not in said, said


def test_a_flat_frame_at_its_mates_level_in_a_simulated_session(
    tmp_path: Path, arm_tablet_12: Path
) -> None:
    """At the level of the images lit from its elevation the frame had read "good"."""
    acq = tmp_path / "acq"
    acq.mkdir()
    for f in [*arm_tablet_12.glob("image_*.jpg"), arm_tablet_12 / "lights.lp"]:
        shutil.copy(f, acq / f.name)
    correct, _ = qa_of(acq, tmp_path / "f0")
    assert "QA verdict: good" in correct and "flat frame" not in correct, correct
    img = cv2.imread(str(acq / "image_005.jpg"))
    cv2.imwrite(str(acq / "image_005.jpg"), np.full_like(img, int(img.mean())))
    said, _ = qa_of(acq, tmp_path / "f")
    assert f"image_005 ({FLAT}" in said, said
    assert "QA verdict: good" not in said


def _gentle_sheet(folder: Path, slope_deg: float = 1.2, side: int = 128) -> Path:
    """A matte sheet of one albedo, undulating by ``slope_deg`` (RMS), under every third light
    of the real acquisition (6-82° elevation), as 16-bit images with little noise: a light near
    the camera axis shades it by the cosine of its slope, under 2 % across the frame."""
    folder.mkdir()
    rng = np.random.default_rng(0)
    z = cv2.GaussianBlur(rng.normal(0.0, 1.0, (side, side)), (0, 0), side / 20)
    gy, gx = np.gradient(z)
    k = np.tan(np.radians(slope_deg)) / float(np.hypot(gx, gy).std())
    normals = np.stack([-gx * k, -gy * k, np.ones_like(z)], axis=-1)
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    entries = []
    for i, e in enumerate(read_lp(REPO / "tests" / "data" / "neuralrti" / "dirs.lp")[::3]):
        light = np.asarray(e.direction, np.float64) / np.linalg.norm(e.direction)
        value = 0.7 * np.clip(normals @ light, 0.0, None) + rng.normal(0.0, 5e-4, z.shape)
        name = f"sheet{i:02d}.png"
        cv2.imwrite(str(folder / name), np.clip(value * 65535, 0, 65535).astype(np.uint16))
        entries.append(LpEntry(name, tuple(light)))
    write_lp(folder / "dirs.lp", entries)
    return folder / "dirs.lp"


def test_a_high_light_on_a_gently_sloped_sheet_is_not_a_flat_frame(tmp_path: Path) -> None:
    """Its highest lights' images vary 1.2-1.7 % across the frame, the session's median image
    11 %: judged against every image they had been called flat; the images of their nearest
    lights vary as little, as a real object's do."""
    said, qa = qa_of(_gentle_sheet(tmp_path / "acq"), tmp_path / "f")
    assert "QA verdict" in said
    named = [c["name"] for c in qa["images"] if any(FLAT in p for p in c["problems"])]
    assert named == [], said


def test_a_flat_frame_among_the_sheets_images_is_named(tmp_path: Path) -> None:
    """A mid-elevation image of the sheet made one level: its nearest lights' images shade."""
    lp = _gentle_sheet(tmp_path / "acq")
    entries = read_lp(lp)
    mid = min(entries, key=lambda e: abs(np.degrees(np.arcsin(e.direction[2])) - 35.0)).name
    img = cv2.imread(str(lp.parent / mid), cv2.IMREAD_UNCHANGED)
    cv2.imwrite(str(lp.parent / mid), np.full_like(img, int(np.median(img))))
    said, qa = qa_of(lp, tmp_path / "f")
    named = [c["name"] for c in qa["images"] if any(FLAT in p for p in c["problems"])]
    assert named == [mid[: -len(".png")]], said


def test_a_flat_frames_light_direction_is_not_judged(tmp_path: Path, arm_tablet_12: Path) -> None:
    """A flat frame holds no picture, so no direction: the verdict had named it a flat frame
    and, beside it, "image_005: best direction 44° from the recorded light, but the recorded
    light explains the image nearly as well (... on this object gloss, shadows or clipping pull
    the best direction)", a judgement of a direction no image of it can give."""
    acq = tmp_path / "acq"
    acq.mkdir()
    for f in [*arm_tablet_12.glob("image_*.jpg"), arm_tablet_12 / "lights.lp"]:
        shutil.copy(f, acq / f.name)
    img = cv2.imread(str(acq / "image_005.jpg"))
    cv2.imwrite(str(acq / "image_005.jpg"), np.full_like(img, int(img.mean())))
    said, qa = qa_of(acq, tmp_path / "f")
    assert f"image_005 ({FLAT}" in said, said
    assert said.count("image_005") == 1, said  # named once: as the flat frame it is
    assert "best direction" not in said and "direction not checked" not in said, said
    (flat,) = [c for c in qa["images"] if c["name"] == "image_005"]
    assert [p for p in flat["problems"] if FLAT not in p] == [], flat["problems"]


def _first(folder: Path, n: int, flat: tuple[str, ...]) -> Path:
    """The replay's first ``n`` images, those of ``flat`` made one grey level (their median)."""
    folder.mkdir()
    entries = read_lp(ACQ)[:n]
    for e in entries:
        img = cv2.imread(str(ACQ.parent / e.name))
        if e.name in flat:
            img = np.full_like(img, int(np.median(img)))
        cv2.imwrite(str(folder / e.name), img)
    write_lp(folder / "dirs.lp", entries)
    return folder / "dirs.lp"


def test_the_flat_frames_left_out_of_the_direction_count_are_said(tmp_path: Path) -> None:
    """Of 6 lit images, 2 of them flat frames, the QA had said "4 image(s) with light", as if
    2 had been dark; the flat frames it did not count are said beside the count."""
    said, _ = qa_of(_first(tmp_path / "acq", 6, ("image05.jpg", "image13.jpg")), tmp_path / "f")
    assert f"image05 ({FLAT}" in said and f"image13 ({FLAT}" in said, said
    assert (
        "light directions not checked: 4 image(s) with light (2 flat frames not counted), too "
        "few to tell a wrong light"
    ) in said, said


def test_no_flat_frame_no_word_of_one_in_the_direction_count(tmp_path: Path) -> None:
    said, _ = qa_of(_first(tmp_path / "acq", 6, ()), tmp_path / "f")
    assert "not counted" not in said and "flat frame" not in said, said
