"""A replay of 12-bit camera data in 16-bit files (`rti-rig run ACQ/lights.lp --out S`) keeps
the recorded codes' own white, and the session's previews, verdict, fit and a resumed adaptive
run all judge the images against it.

Found through the front door after ``rti-rig fit`` learnt to read an imported acquisition's
full scale (:mod:`rti_rig.reconstruct.full_scale`): the replay handed the recorded codes over
as on 65535. A replay of the shipped dome's relief stored as a 12-bit camera stores it, at 3×
its exposure (clipped at 4095 in two thirds of some images), was called "QA verdict: good", its
previews were 16× too dark (a JPEG mean of 49 where the clipped images read 183), and its
session's fit, which trusts rti-rig's own labels, could not see the clip either.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
from colour_files import icc_profile
from conftest import decisions, interrupted, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.devices import Frame
from rti_rig.core.image_files import (
    labelled_white_level,
    linear_tiff_white_level,
    linear_to_srgb8,
    read_linear_tiff,
)
from rti_rig.reconstruct.synthetic import camera_bits_copy
from rti_rig.runtime.session import labelled_white, linear_tiff_labels

runner = CliRunner()
WHITE_65535 = ("--white-level", "65535")
ADAPTIVE_10 = ("--adaptive", "--lights", "10", "--no-verdict")
FIT_NORMALS = ("--no-ptm", "--no-hsh")


@pytest.fixture(scope="module")
def clipped_replay(dome_relief: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple:  # type: ignore[type-arg]
    """The relief as 12-bit data at 3× its exposure, replayed through the CLI (with its verdict)."""
    root = tmp_path_factory.mktemp("replay12")
    acquisition = camera_bits_copy(dome_relief, root / "acq", gain=3.0)
    session = root / "s"
    r = runner.invoke(
        app, ["run", str(acquisition / "lights.lp"), "--out", str(session)], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    return acquisition, session, said(r)


def test_a_clipped_12_bit_replay_is_called_saturated(clipped_replay: tuple) -> None:  # type: ignore[type-arg]
    _, session, text = clipped_replay
    verdict = text[text.index("QA verdict:") :]
    assert verdict.startswith("QA verdict: flawed"), verdict
    assert "saturated" in verdict, verdict
    notices = json.loads((session / "manifest.json").read_text())["notices"]
    assert any("replayed with white level 4095, not 65535" in n for n in notices), notices
    assert "fit the session with --white-level N" in text, text


def test_the_replayed_session_keeps_the_codes_and_says_their_white(clipped_replay: tuple) -> None:  # type: ignore[type-arg]
    acquisition, session, _ = clipped_replay
    tiff = session / "linear" / "image_021.tif"
    recorded = read_linear_tiff(acquisition / "image_021.tif")
    assert np.array_equal(read_linear_tiff(tiff), recorded)  # the codes as recorded
    assert linear_tiff_white_level(tiff) == 4095
    # the preview is the recorded image encoded against 4095 (it was 16x too dark)
    jpeg = cv2.cvtColor(cv2.imread(str(session / "image_021.jpg")), cv2.COLOR_BGR2RGB)
    expected = linear_to_srgb8(recorded, 4095).astype(np.float64)
    assert np.abs(jpeg.astype(np.float64) - expected).mean() < 3.0
    assert jpeg.mean() > 150, jpeg.mean()


def test_the_replayed_session_is_fitted_against_its_labelled_white(
    clipped_replay: tuple,  # type: ignore[type-arg]
    tmp_path: Path,
) -> None:
    _, session, _ = clipped_replay
    out = tmp_path / "f"
    r = runner.invoke(
        app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh"], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    fit = json.loads((out / "fit.json").read_text())
    qa = json.loads((out / "qa.json").read_text())
    assert fit["full_scale"]["how"] == "labelled" and fit["full_scale"]["level"] == 4095, fit
    assert fit["full_scale"]["bits"] == 12, fit
    assert qa["good"] is False and "saturated" in qa["verdict"], qa["verdict"]
    assert "labelled with white level 4095 by the session that wrote them" in said(r)
    # the user's word still decides: judged at 65535, nothing is clipped
    again = tmp_path / "g"
    r = runner.invoke(
        app,
        ["fit", str(session), "--out", str(again), "--no-ptm", "--no-hsh", *WHITE_65535],
    )
    assert r.exit_code == 0, r.output
    assert json.loads((again / "fit.json").read_text())["full_scale"]["how"] == "given"
    assert "saturated" not in json.loads((again / "qa.json").read_text())["verdict"]


def test_a_12_bit_replay_at_half_exposure_is_not_called_under_exposed(
    dome_relief: Path, tmp_path: Path
) -> None:
    acquisition = camera_bits_copy(dome_relief, tmp_path / "acq", gain=0.5)
    session = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(acquisition / "lights.lp"), "--out", str(session)], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "QA verdict: good" in text, text
    assert "read as 12-bit camera data stored unscaled" in text, text
    assert "fit the session with --white-level 65535" in text, text


def _replayed(lp: Path, session: Path):  # type: ignore[no-untyped-def]
    """``rti-rig run LP --out SESSION --lights 9``, which must succeed."""
    r = runner.invoke(
        app, ["run", str(lp), "--out", str(session), "--lights", "9"], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    return r


def _listing_linear(session: Path, dst: Path, scale: float) -> Path:
    """``session`` copied to ``dst`` (without its record) with a ``linear.lp`` listing its
    linear TIFFs, their codes times ``scale`` and their labels kept: an rti-rig session as a
    user may hand it to a replay, by its 16-bit images."""
    import tifffile

    shutil.copytree(session, dst)
    # without its record: the TIFFs' labels alone say whose they are
    (dst / "manifest.json").unlink()
    (dst / "journal.jsonl").unlink()
    lines = (dst / "lights.lp").read_text(encoding="utf-8").splitlines()
    listed = [lines[0]]
    for line in lines[1:]:
        name, *xyz = line.split()
        tiff = dst / "linear" / f"{Path(name).stem}.tif"
        with tifffile.TiffFile(tiff) as tf:
            description = tf.pages[0].description
            codes = tf.asarray()
        dark = np.round(codes * scale).astype(np.uint16)
        tiff.unlink()
        tifffile.imwrite(tiff, dark, description=description, metadata=None)
        listed.append(" ".join([f"linear/{tiff.name}", *xyz]))
    (dst / "linear.lp").write_text("\n".join(listed) + "\n", encoding="utf-8")
    return dst / "linear.lp"


def test_a_dark_session_of_rti_rig_replayed_by_its_tiffs_keeps_65535(
    dome_relief: Path, tmp_path: Path
) -> None:
    """rti-rig's own session (scaled to 65535 as shot) at 1/50 of its exposure, replayed by its
    labelled linear TIFFs: its labels say 65535, which the replay keeps (read from the data,
    its codes under 1400 had been taken for 12-bit data)."""
    lp = _listing_linear(dome_relief, tmp_path / "acq", 1 / 50)
    session = tmp_path / "s"
    r = _replayed(lp, session)
    assert "replayed with white level" not in said(r), said(r)
    assert linear_tiff_white_level(session / "linear" / "image_001.tif") == 65535


def _packed_12_bit(acquisition: Path, icc: bytes | None = None) -> None:
    """Rewrite ``acquisition``'s TIFFs as 12 bits a sample (packed, as some cameras store
    them), with the ICC profile ``icc``: the header says the depth."""
    import tifffile

    for tiff in acquisition.glob("*.tif"):
        codes = tifffile.imread(tiff)
        tifffile.imwrite(tiff, codes, bitspersample=12, photometric="rgb", iccprofile=icc)


def test_12_bit_tiffs_the_replay_converts_from_adobe_rgb_stay_at_65535(
    dome_relief: Path, tmp_path: Path
) -> None:
    """Files the replay converts from the space they say become linear sRGB on 65535: no
    white of their own is read (12 bits a sample had been left out of that rule, and the
    converted frames were then labelled 4095, judged 16x too bright)."""
    acquisition = camera_bits_copy(dome_relief, tmp_path / "acq", gain=0.5)
    _packed_12_bit(acquisition, icc_profile("Adobe RGB (1998)"))
    session = tmp_path / "s"
    r = _replayed(acquisition / "lights.lp", session)
    assert "replayed with white level" not in said(r), said(r)
    assert linear_tiff_white_level(session / "linear" / "image_001.tif") == 65535


def test_a_lost_tiff_of_a_12_bit_replay_is_not_fitted_from_its_jpeg(
    clipped_replay: tuple,  # type: ignore[type-arg]
    tmp_path: Path,
) -> None:
    """The JPEG standing in for a lost linear TIFF was encoded against 4095 and decodes onto
    65535: fitted with the other TIFFs' 4095 codes it would be 16x their scale."""
    _, session, _ = clipped_replay
    copy = tmp_path / "copy"
    shutil.copytree(session, copy)
    (copy / "linear" / "image_005.tif").unlink()
    r = runner.invoke(
        app, ["fit", str(copy), "--out", str(tmp_path / "f"), *FIT_NORMALS], terminal_width=400
    )
    text = said(r)
    assert r.exit_code != 0 and "Traceback" not in text, text
    assert "image_005 is read from its 8-bit JPEG" in text, text
    assert "put the linear TIFF back from a backup copy of the session" in text, text


def test_a_replayed_tiff_is_planned_from_on_65535(clipped_replay: tuple) -> None:  # type: ignore[type-arg]
    """``rti-rig plan`` reads a session's linear TIFF as a preview on 65535 (a 12-bit replay's
    4095 codes had been planned from as an image 16x too dark)."""
    from rti_rig.app.compose import read_preview_image

    acquisition, session, _ = clipped_replay
    recorded = read_linear_tiff(acquisition / "image_021.tif").astype(np.float64)
    seen = read_preview_image(session / "linear" / "image_021.tif").astype(np.float64)
    assert np.abs(seen - np.minimum(recorded * 65535 / 4095, 65535)).max() <= 1.0


def test_tiffs_of_12_bits_a_sample_are_judged_at_4095_by_replay_and_fit(
    dome_relief: Path, tmp_path: Path
) -> None:
    """Dark 12-bit TIFFs (a tenth of the exposure, brightest code under 1024): their headers say
    12 bits, so white is 4095 (the data alone read as 10-bit, 1023). The fit had failed on
    such files outright (their packed rows were read as 16-bit: "short read")."""
    acquisition = camera_bits_copy(dome_relief, tmp_path / "acq", gain=0.1)
    _packed_12_bit(acquisition)
    session = tmp_path / "s"
    r = _replayed(acquisition / "lights.lp", session)
    assert "replayed with white level 4095, not 65535" in said(r), said(r)
    assert "store 12 bits a sample, as their files' headers say" in said(r), said(r)
    out = tmp_path / "f"
    r = runner.invoke(
        app,
        ["fit", str(acquisition), "--out", str(out), "--no-ptm", "--no-hsh"],
        terminal_width=400,
    )
    assert r.exit_code == 0, r.output
    full = json.loads((out / "fit.json").read_text())["full_scale"]
    assert (full["how"], full["level"], full["bits"]) == ("header", 4095, 12), full


def test_an_interrupted_adaptive_replay_of_12_bit_data_resumes_as_it_began(
    dome_relief: Path, tmp_path: Path
) -> None:
    """An adaptive replay of clipped 12-bit data, interrupted and resumed, decides every light
    as the run not interrupted does: the resume takes its white from the session's labels (not
    from a second reading of the acquisition) and weighs each image by it, as the run did live.
    (On this object the chooser's decisions did not change with the white; what this guards is
    the resumed path of such a replay, and the labels' white, tested below.)"""
    acquisition = camera_bits_copy(dome_relief, tmp_path / "acq", gain=3.0)
    whole = tmp_path / "whole"
    r = runner.invoke(
        app,
        ["run", str(acquisition / "lights.lp"), "--out", str(whole), *ADAPTIVE_10],
    )
    assert r.exit_code == 0, r.output
    out = tmp_path / "s"
    interrupted(acquisition / "lights.lp", out, 5, lights=10)
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"], terminal_width=400)
    assert r.exit_code == 0, r.output
    assert decisions(out) == decisions(whole)
    assert {linear_tiff_white_level(t) for t in (out / "linear").glob("*.tif")} == {4095}


@pytest.mark.parametrize(
    ("white", "decode", "expected"),
    [(4095, None, 4095), (65535, None, 65535), (3583, {"mode": "mosaic"}, 65535)],
)
def test_the_live_white_is_the_one_the_label_states(
    white: int,
    decode: dict | None,  # type: ignore[type-arg]
    expected: int,
) -> None:
    """What an adaptive run weighs a frame by live (:func:`labelled_white`) is what its resume
    reads back from the frame's TIFF label; a RAW's or mosaic's label states none (65535)."""
    meta = {"decode": {**decode, "cfa_pattern": "RGGB"}} if decode else {}
    frame = Frame(np.zeros((4, 4, 3), np.uint16), 0.1, 1.0, white, 0.0, meta)
    description, _ = linear_tiff_labels(dict(meta.get("decode") or {}), frame)
    assert labelled_white(frame) == expected
    assert (labelled_white_level(description) or 65535) == expected


def test_jpegs_beside_12_bit_tiffs_are_noted_as_a_mixed_acquisition(
    dome_relief: Path, tmp_path: Path
) -> None:
    """A TIFF of 12 bits a sample is taken as linear, as a 16-bit one is: beside JPEGs, the
    replay notes the mix as ``fit`` does (only headers of exactly 16 bits had counted)."""
    acquisition = camera_bits_copy(dome_relief, tmp_path / "acq", gain=0.5)
    _packed_12_bit(acquisition)
    lp = acquisition / "lights.lp"
    lines = lp.read_text(encoding="utf-8").splitlines()
    name, *xyz = lines[1].split()
    shutil.copy(dome_relief / "image_001.jpg", acquisition / "image_001.jpg")
    (acquisition / name).unlink()
    lines[1] = " ".join(["image_001.jpg", *xyz])
    lp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    r = runner.invoke(app, ["check", str(lp)], terminal_width=400)
    text = said(r)
    assert "Traceback" not in text, text
    assert "mixes 1 8-bit image(s), decoded as sRGB, with 47 16-bit one(s)" in text, text
