"""A tethering program that saves each shot as a TIFF with an alpha channel (grey + alpha,
2 samples per pixel; or RGBA, 4), its ExtraSamples tag saying so, into the watched folder of
the shipped folder-watch dome. Unassociated alpha carries no light: ``rti-rig run`` records
the grey or colour pixels as shot and says once that the alpha was dropped. Associated
(premultiplied) alpha has scaled the pixels by it: the run refuses the file, naming it and
how to save it without alpha. Grey + alpha had stopped the run with "expected an H×W or
H×W×3 image"; premultiplied RGBA had been recorded with its alpha silently cut off."""

from __future__ import annotations

from io import BytesIO
from pathlib import Path

import numpy as np
import pytest
import tifffile
from conftest import journal, tethered_tiffs


def _with_alpha(pixels: np.ndarray, alpha: str) -> bytes:
    out = BytesIO()
    photometric = "rgb" if pixels.shape[2] == 4 else "minisblack"
    tifffile.imwrite(out, pixels, photometric=photometric, extrasamples=[alpha], metadata=None)
    return out.getvalue()


@pytest.mark.parametrize("samples", [2, 4], ids=["grey+alpha", "rgba"])
def test_run_records_the_pixels_of_a_tiff_with_alpha_and_says_alpha_was_dropped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, samples: int
) -> None:
    rng = np.random.default_rng(7)
    shots = [rng.integers(1000, 60000, (40, 56, samples), dtype=np.uint16) for _ in range(2)]
    files = [_with_alpha(p, "unassalpha") for p in shots]
    with tifffile.TiffFile(BytesIO(files[0])) as tif:  # the files are as described
        page = tif.pages[0]
        assert page.samplesperpixel == samples and tuple(page.extrasamples) == (2,)
    r, said, _tether, out, lit_at_end = tethered_tiffs(tmp_path, monkeypatch, files)
    assert r.exit_code == 0, said
    assert "Traceback" not in said, said
    for n, shot in enumerate(shots, 1):
        image = tifffile.imread(out / "linear" / f"image_{n:03d}.tif")
        expected = shot[..., :3] if samples == 4 else shot[..., 0]
        assert image.shape == expected.shape, image.shape
        assert np.array_equal(image, expected)  # the shot's own pixels, the alpha left out
    assert said.count("alpha channel") == 1, said  # said once, not once per image
    assert "the watched TIFFs have an alpha channel" in said and "dropped" in said, said
    assert "[2 of 2 images]" in said, said
    assert all(any("alpha" in n for n in s.get("notices", [])) for s in journal(out)), out
    assert lit_at_end == []


def test_run_refuses_a_tiff_with_premultiplied_alpha_naming_it_and_the_fix(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(8)
    shot = rng.integers(1000, 60000, (40, 56, 4), dtype=np.uint16)
    r, said, tether, out, lit_at_end = tethered_tiffs(
        tmp_path, monkeypatch, [_with_alpha(shot, "assocalpha")]
    )
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert "IMG_0001.tif" in said and "premultiplied" in said, said
    assert "without alpha" in said, said
    assert (tether / "IMG_0001.tif").exists()  # the shot is left where it was saved
    assert not list(out.glob("linear/image_*.tif"))  # nothing recorded from it
    assert lit_at_end == []


def _grey_with_extras(pixels: np.ndarray, extras: list[str]) -> bytes:
    out = BytesIO()
    tifffile.imwrite(
        out,
        pixels,
        photometric="minisblack",
        planarconfig="contig",
        extrasamples=extras,
        metadata=None,
    )
    return out.getvalue()


@pytest.mark.parametrize(
    "extras", [["unassalpha", "unspecified"], ["unspecified"] * 3], ids=["grey+2", "grey+3"]
)
def test_run_records_the_grey_of_a_grey_tiff_with_several_extra_samples(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, extras: list[str]
) -> None:
    """Grey (MinIsBlack) with two or three extra samples has 3 or 4 per pixel: the grey is
    the first, as its header counts them. It had been recorded as an RGB image of the grey
    and its extra samples (their count, not the header, decided grey or colour)."""
    rng = np.random.default_rng(9)
    n = 1 + len(extras)
    shot = rng.integers(1000, 60000, (40, 56, n), dtype=np.uint16)
    data = _grey_with_extras(shot, extras)
    with tifffile.TiffFile(BytesIO(data)) as tif:  # the file is as described
        page = tif.pages[0]
        assert page.photometric == 1 and page.samplesperpixel == n
        assert len(page.extrasamples) == len(extras)
    r, said, _tether, out, lit_at_end = tethered_tiffs(tmp_path, monkeypatch, [data, data])
    assert r.exit_code == 0, said
    assert "Traceback" not in said, said
    image = tifffile.imread(out / "linear" / "image_001.tif")
    assert image.shape == shot.shape[:2], image.shape  # grey, not colour
    assert np.array_equal(image, shot[..., 0])
    assert said.count("extra channel of no stated use") == 1, said
    assert "carries no light" not in said, said  # an unspecified sample is not claimed alpha
    assert lit_at_end == []


def test_a_resumed_session_of_tiffs_with_alpha_says_the_alpha_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A run stopped after its first image (the camera saved nothing more) and resumed: the
    session's notices cover both runs' images. Each run named its own first file in the
    notice, so the resumed session said it twice, each calling another file the first."""
    from conftest import folder_watch_config, tethered_run

    rng = np.random.default_rng(10)
    shots = [rng.integers(1000, 60000, (40, 56, 4), dtype=np.uint16) for _ in range(2)]
    files = [(f"IMG_{n:04d}.tif", _with_alpha(p, "unassalpha")) for n, p in enumerate(shots, 1)]
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=4.0, tiffs=True)
    out = tmp_path / "s"
    first = tethered_run(monkeypatch, cfg, tether, files[:1], out)  # no file for light 2
    assert first.result.exit_code != 0, first.said
    assert (out / "linear" / "image_001.tif").is_file(), first.said
    again = tethered_run(monkeypatch, cfg, tether, files[1:], out, resume=True)
    assert again.result.exit_code == 0, again.said
    assert "Traceback" not in again.said, again.said
    assert again.said.count("alpha channel") == 1, again.said  # one notice, both runs
    assert "[2 of 2 images]" in again.said, again.said
    assert again.lit_at_end == []
