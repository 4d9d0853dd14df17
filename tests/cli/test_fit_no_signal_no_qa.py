"""`rti-rig fit --no-qa` says when its outputs are from images that hold no signal.

An acquisition black throughout (a lens cap, lights that never fired) or saturated throughout
(an exposure far too long) had its normal maps written without a word when the QA was left
out: a least-squares fit of nothing is still a normal map.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, read_lp, write_lp
from tests.fit_sessions import dome_lights, make_session

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
#: "is" or "are": the test that nothing is said must not pass on the verb alone
SAID = "from images that hold no signal"


def _acquisition(folder: Path, value: int, lit: int = 0) -> tuple[Path, list[str]]:
    """The replay's 18 lights over flat images of ``value``, its first ``lit`` images its own
    (real, lit) photographs."""
    folder.mkdir()
    entries = read_lp(ACQ)
    for k, e in enumerate(entries):
        img = np.full((64, 64, 3), value, np.uint8)
        if k < lit:
            img = cv2.resize(cv2.imread(str(ACQ.parent / e.name)), (64, 64))
        cv2.imwrite(str(folder / e.name), img)
    write_lp(folder / "dirs.lp", entries)
    return folder / "dirs.lp", [Path(e.name).stem for e in entries]


def _fit(source: Path, out: Path, *extra: str) -> str:
    r = CliRunner().invoke(app, ["fit", str(source), "--out", str(out), *extra])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    return said


@pytest.mark.parametrize(("value", "kind"), [(0, "black"), (255, "saturated")])
def test_an_acquisition_without_signal_is_said_naming_its_images(
    tmp_path: Path, value: int, kind: str
) -> None:
    lp, stems = _acquisition(tmp_path / "acq", value)
    said = _fit(lp, tmp_path / "f", "--no-qa")
    assert (tmp_path / "f" / "normals.npy").exists()  # written, and now said
    assert said.count(SAID) == 1, said
    assert "every image (18) is black" in said
    assert f"{stems[0]} ({kind}), {stems[1]} ({kind})" in said
    assert "and 6 more" in said  # 12 named of 18


@pytest.mark.parametrize(("value", "kind"), [(0, "black"), (255, "saturated")])
def test_relighting_files_without_normals_are_said_too(
    tmp_path: Path, value: int, kind: str
) -> None:
    # --no-normals --no-qa had written fit.ptm and fit.rti from a black acquisition silently
    lp, stems = _acquisition(tmp_path / "acq", value)
    out = tmp_path / "f"
    said = _fit(lp, out, "--no-qa", "--no-normals")
    assert (out / "fit.ptm").exists() and not (out / "normals.npy").exists()
    assert said.count(SAID) == 1, said
    assert "fit.ptm and fit.rti are from images that hold no signal" in said
    assert "normal maps" not in said.split(SAID)[0].rsplit("warning:", 1)[-1]
    assert "every image (18) is black" in said and f"{stems[0]} ({kind})" in said


def test_with_normals_every_output_is_named(tmp_path: Path) -> None:
    lp, _ = _acquisition(tmp_path / "acq", 0)
    said = _fit(lp, tmp_path / "f", "--no-qa")
    assert "fit.ptm, fit.rti and the normal maps are from images that hold no signal" in said


def test_images_left_that_cannot_determine_a_normal_are_said(tmp_path: Path) -> None:
    lp, stems = _acquisition(tmp_path / "acq", 0, lit=2)
    said = _fit(lp, tmp_path / "f", "--no-qa")
    assert "16 of the 18 images are black" in said, said
    assert f"{stems[2]} (black)" in said and f"{stems[0]} (" not in said
    assert (
        "the 2 others are fewer than fit.ptm's 6 and fit.rti's 4 coefficients per pixel and "
        "cannot determine a normal by themselves" in said
    ), said


def test_one_image_left_that_cannot_determine_a_normal_is_itself(tmp_path: Path) -> None:
    lp, _ = _acquisition(tmp_path / "acq", 0, lit=1)
    said = _fit(lp, tmp_path / "f", "--no-qa")
    assert "17 of the 18 images are black" in said, said
    assert "the 1 other is fewer than" in said, said
    assert "and cannot determine a normal by itself." in said, said


def _raking() -> np.ndarray:
    """12 raking lights at azimuths 0° and 180° only, 10°-75° up: relighting documentation
    whose lights cannot determine a normal (one upright plane through the object)."""
    out = []
    for az in np.radians([0.0, 180.0]):
        for el in np.radians([10.0, 20.0, 30.0, 45.0, 60.0, 75.0]):
            out.append((np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)))
    return np.array(out)


def test_a_relighting_only_acquisition_with_one_black_image_is_left_to_the_qa(
    tmp_path: Path,
) -> None:
    # its 11 lit images "cannot determine a normal", which fit.ptm and fit.rti never needed:
    # they had been said to be "from images that hold no signal"
    session, _, _ = make_session(tmp_path / "s", size=(48, 48), lights=_raking(), black=4)
    said = _fit(session, tmp_path / "f", "--no-qa")
    assert (tmp_path / "f" / "fit.ptm").exists() and (tmp_path / "f" / "fit.rti").exists()
    assert not (tmp_path / "f" / "normals.npy").exists()  # said separately: undetermined
    assert SAID not in said, said


def test_a_relighting_only_acquisition_black_throughout_is_said(tmp_path: Path) -> None:
    folder = tmp_path / "acq"
    folder.mkdir()
    entries = [
        LpEntry(f"raking_{k:02d}.png", tuple(float(c) for c in d)) for k, d in enumerate(_raking())
    ]
    for e in entries:
        cv2.imwrite(str(folder / e.name), np.zeros((48, 48, 3), np.uint8))
    write_lp(folder / "dirs.lp", entries)
    said = _fit(folder / "dirs.lp", tmp_path / "f", "--no-qa")
    assert said.count(SAID) == 1, said
    assert "fit.ptm and fit.rti are from images that hold no signal" in said
    assert "every image (12) is black" in said


def test_fewer_lit_images_than_a_ptm_has_coefficients_are_said_naming_fit_ptm(
    tmp_path: Path,
) -> None:
    # 6 lights, one black: the 5 lit ones determine a normal and an order-1 HSH (4 terms)
    # but not a PTM's 6 coefficients
    session, _, _ = make_session(tmp_path / "s", size=(48, 48), lights=dome_lights()[::6], black=2)
    said = _fit(session, tmp_path / "f", "--no-qa", "--hsh-order", "1")
    assert said.count(SAID) == 1, said
    assert "fit.ptm is from images that hold no signal: 1 of the 6 images is black" in said
    assert "image_003 (black); the 5 others are fewer than fit.ptm's 6 coefficients" in said
    assert "fit.rti" not in said.split(SAID)[0].rsplit("warning:", 1)[-1]
    assert "normal maps" not in said.split(SAID)[0].rsplit("warning:", 1)[-1]


def test_one_misfire_among_lit_images_is_left_to_the_qa(tmp_path: Path) -> None:
    session, _, _ = make_session(tmp_path / "s", size=(48, 48), black=4)
    said = _fit(session, tmp_path / "f", "--no-qa")
    assert SAID not in said
    assert (tmp_path / "f" / "normals.npy").exists()


def test_with_the_qa_it_names_them_itself(tmp_path: Path) -> None:
    lp, _ = _acquisition(tmp_path / "acq", 0)
    said = _fit(lp, tmp_path / "f", "--no-ptm")
    assert SAID not in said  # said once, by the QA
    assert said.count("no light in any image") == 1, said


def test_a_small_object_on_black_velvet_is_not_called_no_signal(tmp_path: Path) -> None:
    """An object covering under 1 % of the frame on a black ground: an image had been called
    black when 99 % of its sampled values were, so every image of such an acquisition was said
    to hold no signal. Its lit pixels (a 5 x 5 patch of 64 x 64, 0.6 %) are signal."""
    folder = tmp_path / "acq"
    folder.mkdir()
    entries = read_lp(ACQ)
    for e in entries:
        img = np.zeros((64, 64, 3), np.uint8)
        photo = cv2.resize(cv2.imread(str(ACQ.parent / e.name)), (64, 64))
        img[30:35, 30:35] = np.maximum(photo[30:35, 30:35], 20)  # lit, if dimly
        cv2.imwrite(str(folder / e.name), img)
    write_lp(folder / "dirs.lp", entries)
    said = _fit(folder / "dirs.lp", tmp_path / "f", "--no-qa")
    assert SAID not in said, said
    assert (tmp_path / "f" / "normals.npy").exists()
