"""A session under-exposed throughout is named, with what to do, through the front door.

Found by a QA sweep: the shipped simulated dome run at 1/50 of its exposure
(``camera.exposure_s = 0.001``) was "QA verdict: good", its brightest pixels at about 1 % of
full scale, its expected normal error 7× the correctly exposed session's and its JPEGs using
30 of 256 levels. Every image agrees with the others, so no per-image check could see it.
A correctly exposed session lit only from grazing lights (the dimmest the shipped dome
gives) and a real acquisition are not called so.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
from conftest import REPO, qa_of, said, shipped_variant
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.reconstruct.qa_underexposed import UNDEREXPOSED, underexposed_problem

runner = CliRunner()
REAL = REPO / "tests" / "data" / "neuralrti_replay"


def _run(config: Path, out: Path, *extra: str) -> str:
    r = runner.invoke(app, ["run", str(config), "--out", str(out), "--lights", "12", *extra])
    assert r.exit_code == 0, r.output
    return said(r)


@pytest.mark.e2e
def test_a_session_at_a_fiftieth_of_its_exposure_is_told_to_shoot_again_longer(
    tmp_path: Path,
) -> None:
    config = shipped_variant(
        tmp_path, "simulated_dome.toml", (("exposure_s = 0.05", "exposure_s = 0.001"),)
    )

    text = _run(config, tmp_path / "dark")

    assert "QA verdict: reshoot: image_001 ... image_012 (12 images: under-exposed" in text, text
    assert "of full scale" in text and "× the exposure brings them to 50%" in text, text
    # a planned session keeps one exposure: the advice is a new session, as the run takes it
    assert "with a longer camera.exposure_s (or more light), or with --auto-exposure" in text
    assert "reshoot with more exposure" not in text, text
    _, qa = qa_of(tmp_path / "dark", tmp_path / "fit")
    assert qa["good"] is False and len(qa["reshoot"]) == 12, qa["verdict"]
    peaks = [c["peak_level"] for c in qa["images"]]  # each image's share of the range
    assert 0.001 < max(peaks) < qa["thresholds"]["underexposed_peak"], peaks
    # the advice, followed as printed, gives a session the verdict passes
    assert "QA verdict: good" in _run(config, tmp_path / "metered", "--auto-exposure")


@pytest.mark.e2e
def test_a_grazing_session_of_a_matte_plate_is_not_called_under_exposed(tmp_path: Path) -> None:
    """The dimmest correct session of the shipped dome: a matte plate lit only from its 10°
    ring, its brightest pixels at about 7 % of full scale."""
    config = shipped_variant(
        tmp_path, "simulated_dome.toml", (('name = "relief"', 'name = "flat"'),)
    )

    text = _run(config, tmp_path / "low", "--max-elevation-deg", "15")

    assert "QA verdict:" in text and UNDEREXPOSED not in text, text


def _srgb_linear(v: np.ndarray) -> np.ndarray:
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def _linear_srgb(v: np.ndarray) -> np.ndarray:
    v = np.clip(v, 0.0, 1.0)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)


@pytest.mark.e2e
def test_an_imported_acquisition_under_exposed_is_named_as_the_acquisitions(
    tmp_path: Path,
) -> None:
    """A real acquisition (NeuralRTI's, a gilded icon) at 1/50 of its light is named, with no
    advice to reshoot an object that is not under this dome; as recorded, it is not."""
    dark = tmp_path / "dark"
    dark.mkdir()
    for image in sorted(REAL.glob("*.jpg")):
        px = cv2.imread(str(image), cv2.IMREAD_UNCHANGED).astype(np.float64) / 255.0
        darker = np.round(_linear_srgb(_srgb_linear(px) / 50.0) * 255.0).astype(np.uint8)
        cv2.imwrite(str(dark / image.name), darker, [cv2.IMWRITE_JPEG_QUALITY, 95])
    shutil.copy(REAL / "dirs.lp", dark / "dirs.lp")

    text, qa = qa_of(dark / "dirs.lp", tmp_path / "fit")

    assert "QA verdict: flawed: image01 ... image69 (18 images: under-exposed" in text, text
    assert "so they are in the acquisition: its fit is the noisier for it" in text, text
    assert "reshoot with more exposure" not in text and qa["good"] is False
    # a fault of every image: leaving the images named out of the .lp leaves none
    assert "mended only by photographing the object again, where it can be" in text, text
    assert "leave the images named out" not in text, text

    as_recorded, _ = qa_of(REAL / "dirs.lp", tmp_path / "fit-real")
    assert UNDEREXPOSED not in as_recorded, as_recorded


def test_no_full_scale_or_a_black_session_claims_no_under_exposure() -> None:
    """Float frames have no full scale (NaN): nothing is claimed; a black session is the
    black-throughout check's; the limit is the brightest image's, not every image's."""
    assert underexposed_problem(np.array([0.01, np.nan])) is None
    assert underexposed_problem(np.zeros(4)) is None
    assert underexposed_problem(np.array([0.004, 0.2])) is None  # one image reaches the range
    words = underexposed_problem(np.array([0.004, 0.01]))
    assert words is not None and "reach 1.0% of full scale" in words and "about 50×" in words


@pytest.mark.e2e
def test_a_session_at_a_five_hundredth_blames_no_gloss(tmp_path: Path) -> None:
    """At 1/500 of its exposure the shipped dome's frames are black (said once, as such), and
    the light directions they cannot tell had been put down to "a glossy, saturated or
    non-Lambertian surface" of a matte relief."""
    config = shipped_variant(
        tmp_path, "simulated_dome.toml", (("exposure_s = 0.05", "exposure_s = 0.0001"),)
    )

    text = _run(config, tmp_path / "black")

    assert "(12 images: next to no light in any image" in text, text
    assert "light directions not checked: images this dark tell no light" in text, text
    assert "glossy" not in text and UNDEREXPOSED not in text, text


@pytest.fixture(scope="module")
def dark_session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The shipped dome at 1/50 of its exposure, 12 lights: a session under-exposed throughout."""
    root = tmp_path_factory.mktemp("dark")
    config = shipped_variant(
        root, "simulated_dome.toml", (("exposure_s = 0.05", "exposure_s = 0.001"),)
    )
    _run(config, root / "s")
    return root / "s"


@pytest.mark.e2e
def test_under_an_edited_lp_the_under_exposure_is_said_once(
    dark_session: Path, tmp_path: Path
) -> None:
    """Two lines of lights.lp swapped: the verdict leads with the .lp and lists what it found
    as well, where the under-exposure had been said once per image (6 000 characters)."""
    session = tmp_path / "s"
    shutil.copytree(dark_session, session)
    lp = session / "lights.lp"
    lines = lp.read_text(encoding="utf-8").splitlines()
    lines[1], lines[2] = (
        lines[1].split()[0] + " " + " ".join(lines[2].split()[1:]),
        (lines[2].split()[0] + " " + " ".join(lines[1].split()[1:])),
    )
    lp.write_text("\n".join(lines) + "\n", encoding="utf-8")

    text, qa = qa_of(session, tmp_path / "fit")

    assert text.count(UNDEREXPOSED) == 1, text
    assert "image_001 ... image_012 (12 images: under-exposed throughout" in text, text
    assert qa["good"] is False


@pytest.mark.e2e
def test_an_unfinished_under_exposed_session_is_not_offered_a_resume(
    dark_session: Path, tmp_path: Path
) -> None:
    """A resume keeps the session's exposure: it had been offered beside the advice to shoot
    a new session with a longer one."""
    session = tmp_path / "s"
    shutil.copytree(dark_session, session)
    manifest = json.loads((session / "manifest.json").read_text(encoding="utf-8"))
    manifest["runner"]["finish_reason"] = "cancelled"
    (session / "manifest.json").write_text(json.dumps(manifest), encoding="utf-8")

    text, _ = qa_of(session, tmp_path / "fit")

    assert "the session is not finished" in text and UNDEREXPOSED in text, text
    assert "--resume" not in text, text
    assert "a resume keeps the session's exposure and the images taken so far" in text, text
