"""`rti-rig fit` reads every input kind once and the same: uncompressed TIFF sessions (written
now), zlib TIFF sessions (written before 2026-11-24), and JPEG acquisitions beside an ``.lp``.
Also the two row readers the fit streams through, against the arrays they hold."""

from __future__ import annotations

import json
import shutil
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
import pytest
import tifffile
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import linear_to_srgb8, write_linear_tiff
from rti_rig.core.lp_format import LpEntry, read_lp, write_lp
from rti_rig.core.raw_rows import RawRows
from rti_rig.core.tiff_rows import TiffRows

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

runner = CliRunner()
FIT = ["--model", "ps", "--no-qa", "--no-ptm", "--no-hsh"]


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.degrees(np.arccos(np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)))


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("inputs")
    session, _, _ = make_session(root / "tiff", size=(96, 112))
    zlib, jpeg = root / "zlib", root / "jpeg"
    (zlib / "linear").mkdir(parents=True)
    jpeg.mkdir()
    shutil.copy(session / "lights.lp", zlib / "lights.lp")
    entries = []
    for e in read_lp(session / "lights.lp"):
        stem = Path(e.name).stem
        px = tifffile.imread(session / "linear" / f"{stem}.tif")
        write_linear_tiff(zlib / "linear" / f"{stem}.tif", px, compression="zlib")
        srgb = linear_to_srgb8(px, 65535)
        cv2.imwrite(str(jpeg / f"{stem}.jpg"), srgb[..., ::-1], [cv2.IMWRITE_JPEG_QUALITY, 98])
        entries.append(LpEntry(f"{stem}.jpg", e.direction))
    write_lp(jpeg / "acquisition.lp", entries)
    return {"tiff": session, "zlib": zlib, "jpeg": jpeg / "acquisition.lp"}


def _fit(source: Path, out: Path) -> tuple[np.ndarray, np.ndarray]:
    r = runner.invoke(app, ["fit", str(source), "--out", str(out), *FIT])
    assert r.exit_code == 0, r.output
    return np.load(out / "normals.npy"), np.load(out / "albedo.npy")


def test_sessions_now_write_uncompressed_tiffs_read_in_place(inputs: dict[str, Path]) -> None:
    tif = next((inputs["tiff"] / "linear").glob("*.tif"))
    with tifffile.TiffFile(tif) as tf:
        assert int(tf.pages[0].compression) == 1
    assert TiffRows(tif).reads_in_place
    old = next((inputs["zlib"] / "linear").glob("*.tif"))
    assert not TiffRows(old).reads_in_place


def test_old_zlib_sessions_fit_exactly_like_new_ones(inputs: dict[str, Path], tmp_path) -> None:
    n_new, a_new = _fit(inputs["tiff"], tmp_path / "new")
    n_old, a_old = _fit(inputs["zlib"], tmp_path / "old")
    np.testing.assert_array_equal(n_old, n_new)
    np.testing.assert_array_equal(a_old, a_new)


def test_jpeg_acquisition_fits_like_the_linear_session(inputs: dict[str, Path], tmp_path) -> None:
    """8-bit sRGB quantisation and JPEG loss only: normals within a degree (median)."""
    n_tif, _ = _fit(inputs["tiff"], tmp_path / "tif")
    n_jpg, _ = _fit(inputs["jpeg"], tmp_path / "jpg")
    assert float(np.median(_angles(n_jpg, n_tif))) < 1.0


@pytest.mark.parametrize("compression", [None, "zlib"])
def test_tiff_rows_return_the_rows_asked_for(tmp_path: Path, compression: str | None) -> None:
    rng = np.random.default_rng(0)
    for shape in [(301, 207, 3), (130, 77)]:
        a = rng.integers(0, 65535, shape).astype(np.uint16)
        path = tmp_path / f"{compression}_{len(shape)}.tif"
        write_linear_tiff(path, a, compression=compression)
        rows = TiffRows(path)
        for sl in [slice(0, shape[0]), slice(5, 70), slice(63, 65), slice(shape[0] - 1, None)]:
            np.testing.assert_array_equal(rows[sl], a[sl])
        np.testing.assert_array_equal(np.asarray(rows), a)


def test_raw_rows_read_back_what_was_written_and_map_through_the_lut() -> None:
    rng = np.random.default_rng(1)
    a = rng.integers(0, 255, (40, 30, 3)).astype(np.uint8)
    b = rng.integers(0, 65535, (40, 30, 3)).astype(np.uint16)
    lut = (np.arange(256, dtype=np.uint16) * 7).astype(np.uint16)
    with tempfile.TemporaryFile() as store:
        store.write(a.tobytes())
        store.write(b.tobytes())
        store.flush()
        ra = RawRows(store, 0, a.shape, a.dtype, lut)
        rb = RawRows(store, a.nbytes, b.shape, b.dtype)
        assert ra.dtype == np.uint16 and rb.dtype == np.uint16
        np.testing.assert_array_equal(ra[3:17], lut[a[3:17]])
        np.testing.assert_array_equal(rb[39:40], b[39:40])
        np.testing.assert_array_equal(np.asarray(rb), b)
        np.testing.assert_array_equal(rb[::2], b[::2])
        band = np.empty((14, 30, 3), dtype=np.float32)
        ra.rows_float32(slice(3, 17), 1 / 65535, band)
        np.testing.assert_allclose(band, lut[a[3:17]] / np.float32(65535), rtol=1e-6)
        rb.rows_float32(slice(3, 17), 0.5, band)
        np.testing.assert_array_equal(band, b[3:17] * np.float32(0.5))


@pytest.mark.parametrize("kind", ["tiff", "zlib"])
def test_a_truncated_image_is_a_named_error_not_a_traceback(
    inputs: dict[str, Path], tmp_path: Path, kind: str
) -> None:
    """A session copied badly (one TIFF cut short): the fit names the file and says what to do,
    exit code 2, no traceback."""
    session = tmp_path / kind
    shutil.copytree(inputs[kind], session)
    victim = sorted((session / "linear").glob("*.tif"))[3]
    data = victim.read_bytes()
    victim.write_bytes(data[: len(data) * 2 // 3])
    r = runner.invoke(app, ["fit", str(session), "--out", str(tmp_path / "out"), *FIT])
    assert r.exit_code == 2, r.output
    text = " ".join(r.output.split())
    assert victim.name in text and ("truncated" in text or "cannot" in text), text
    assert r.exception is None or isinstance(r.exception, SystemExit)


def test_an_lzw_tiff_acquisition_fits_exactly_like_the_session(
    inputs: dict[str, Path], tmp_path: Path
) -> None:
    """LZW is what OpenCV, Photoshop and ImageMagick write: it had stopped the fit with a
    traceback asking for the 'imagecodecs' package (now a dependency)."""
    lzw = tmp_path / "lzw"
    (lzw / "linear").mkdir(parents=True)
    shutil.copy(inputs["tiff"] / "lights.lp", lzw / "lights.lp")
    entries = []
    for e in read_lp(inputs["tiff"] / "lights.lp"):
        stem = Path(e.name).stem
        px = tifffile.imread(inputs["tiff"] / "linear" / f"{stem}.tif")
        tifffile.imwrite(lzw / f"{stem}.tif", px, compression="lzw")
        entries.append(LpEntry(f"{stem}.tif", e.direction))
    write_lp(lzw / "acquisition.lp", entries)
    n_new, a_new = _fit(inputs["tiff"], tmp_path / "new")
    n_lzw, a_lzw = _fit(lzw / "acquisition.lp", tmp_path / "out")
    np.testing.assert_array_equal(n_lzw, n_new)
    np.testing.assert_array_equal(a_lzw, a_new)


@pytest.mark.parametrize("damage", ["empty", "header offset"])
def test_a_tiff_that_is_no_tiff_is_a_named_error_and_a_batch_goes_on(
    inputs: dict[str, Path], tmp_path: Path, damage: str
) -> None:
    """An empty TIFF, or one whose first-page offset is overwritten: tifffile's own exception
    (TiffFileError, IndexError) had reached the user as a traceback and stopped a batch."""
    bad = tmp_path / "bad"
    shutil.copytree(inputs["tiff"], bad)
    victim = sorted((bad / "linear").glob("*.tif"))[2]
    if damage == "empty":
        victim.write_bytes(b"")
    else:
        data = bytearray(victim.read_bytes())
        data[4:8] = b"\xff\xff\xff\x7f"
        victim.write_bytes(bytes(data))
    r = runner.invoke(app, ["fit", str(bad), "--out", str(tmp_path / "out"), *FIT])
    assert r.exit_code == 2, r.output
    text = " ".join(r.output.split())
    assert victim.name in text and "cannot be read as a TIFF" in text, text
    assert r.exception is None or isinstance(r.exception, SystemExit)
    # in a batch the damaged session is reported and the next one still fitted
    r = runner.invoke(
        app, ["fit", str(bad), str(inputs["tiff"]), "--out", str(tmp_path / "batch"), *FIT]
    )
    assert r.exit_code == 2, r.output
    assert (tmp_path / "batch" / inputs["tiff"].name / "normals.npy").is_file()


def test_a_session_missing_a_linear_tiff_says_its_8_bit_file_stood_in(
    inputs: dict[str, Path], tmp_path: Path
) -> None:
    """linear/image_005.tif gone: the fit reads image_005.jpg instead, and says so (it had mixed
    lossy 8-bit data into the linear fit without a word)."""
    session = tmp_path / "s"
    shutil.copytree(inputs["tiff"], session)
    stem = Path(read_lp(session / "lights.lp")[4].name).stem
    (session / "linear" / f"{stem}.tif").unlink()
    cv2.imwrite(
        str(session / f"{stem}.jpg"),
        linear_to_srgb8(tifffile.imread(inputs["tiff"] / "linear" / f"{stem}.tif"), 65535)[
            ..., ::-1
        ],
    )
    r = runner.invoke(app, ["fit", str(session), "--out", str(tmp_path / "out"), *FIT])
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert "1 of 36 image(s) have no readable linear/ TIFF" in text and f"{stem}.jpg" in text, text
    notes = json.loads((tmp_path / "out" / "fit.json").read_text())["input_notes"]
    assert any("read from their 8-bit file instead" in n for n in notes)
    # a session whose every TIFF is there says nothing of the kind
    r = runner.invoke(app, ["fit", str(inputs["tiff"]), "--out", str(tmp_path / "o2"), *FIT])
    assert "no linear/ TIFF" not in r.output


def test_the_dask_readers_image_of_a_jpeg_is_rows_on_disk_not_pixels_in_memory(
    inputs: dict[str, Path],
) -> None:
    """A Dask worker keeps the acquisitions it opened: a JPEG must be held as rows in a
    temporary file (RawRows), read on demand, with the plain fit's values."""
    from rti_rig.app.usecases.fit import load_acquisition, read_image

    jpg = sorted(inputs["jpeg"].parent.glob("*.jpg"))[2]
    img = read_image(jpg)
    assert isinstance(img, RawRows) and not isinstance(img, np.ndarray)
    frames, _, names, _ = load_acquisition(inputs["jpeg"])
    plain = frames[names.index(jpg.stem)]
    np.testing.assert_array_equal(img[5:9], plain[5:9])


def test_decoded_rows_close_their_file_when_released() -> None:
    """A released decode store closes its file itself: left unclosed to the garbage collector
    it raised a ResourceWarning inside a later fit, which recorded it in fit.json."""
    import gc
    import warnings

    from rti_rig.core.raw_rows import DecodedStore

    store = DecodedStore()
    fh = store.file
    img = np.arange(12, dtype=np.uint16).reshape(3, 4)
    fh.write(img.tobytes())
    fh.flush()
    rows = RawRows(store, 0, img.shape, img.dtype)
    del store
    assert np.array_equal(rows[1:3], img[1:3])  # the rows keep their store alive
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        del rows
        gc.collect()
    assert fh.closed
    # only this store's file: gc.collect() also finalises what earlier tests left behind
    own = f"name={fh.name!r}"
    mine = [w for w in caught if issubclass(w.category, ResourceWarning) and own in str(w.message)]
    assert not mine


def test_a_fit_records_its_own_warnings_not_the_process_s(
    inputs: dict[str, Path], tmp_path: Path, monkeypatch
) -> None:
    """fit.json lists what concerns the fit (here a numerical warning raised while fitting), not
    a ResourceWarning or a DeprecationWarning that happened to be raised while it ran."""
    import json
    import warnings

    from rti_rig.app.usecases import fit as fit_mod

    real = fit_mod.fit_band

    def noisy(*args, **kwargs):  # type: ignore[no-untyped-def]
        warnings.warn("unclosed file <_io.BufferedRandom name=17>", ResourceWarning, stacklevel=1)
        warnings.warn("some library API is deprecated", DeprecationWarning, stacklevel=1)
        warnings.warn("overflow while fitting this band", RuntimeWarning, stacklevel=1)
        return real(*args, **kwargs)

    monkeypatch.setattr(fit_mod, "fit_band", noisy)
    out = tmp_path / "fit"
    r = runner.invoke(app, ["fit", str(inputs["tiff"]), "--model", "ps", "--out", str(out)])
    assert r.exit_code == 0, r.output
    said = json.loads((out / "fit.json").read_text(encoding="utf-8"))["warnings"]
    assert any("overflow while fitting" in w for w in said), said
    assert not any("unclosed file" in w or "deprecated" in w for w in said), said


def _rgba(px: np.ndarray) -> np.ndarray:
    return np.dstack([px, np.full(px.shape[:2], 65535, np.uint16)])


@pytest.mark.parametrize("layout", ["planar tiff", "rgba tiff", "rgba png"])
def test_planar_and_alpha_images_fit_exactly_like_the_session(
    inputs: dict[str, Path], tmp_path: Path, layout: str
) -> None:
    """A planar TIFF (Photoshop's "Per Channel" order) decodes samples first, (3, H, W), and an
    RGBA image has a fourth sample: both had gone through the whole fit to stop at its export
    ("export needs grey or RGB coefficients, got (6, 1, 96, 112)"), and RGBA PNGs were read
    alpha first. The alpha carries no light: dropped, as the replay rig drops it."""
    acq = tmp_path / "acq"
    acq.mkdir()
    entries = []
    for e in read_lp(inputs["tiff"] / "lights.lp"):
        stem = Path(e.name).stem
        px = tifffile.imread(inputs["tiff"] / "linear" / f"{stem}.tif")
        if layout == "planar tiff":
            name = f"{stem}.tif"
            tifffile.imwrite(
                acq / name, np.moveaxis(px, -1, 0), photometric="rgb", planarconfig="separate"
            )
        elif layout == "rgba tiff":
            name = f"{stem}.tif"
            tifffile.imwrite(acq / name, _rgba(px), photometric="rgb", extrasamples=["unassalpha"])
        else:
            name = f"{stem}.png"
            cv2.imwrite(str(acq / name), _rgba(px)[..., [2, 1, 0, 3]])
        entries.append(LpEntry(name, e.direction))
    write_lp(acq / "acquisition.lp", entries)
    n_ref, a_ref = _fit(inputs["tiff"], tmp_path / "ref")
    n_got, a_got = _fit(acq / "acquisition.lp", tmp_path / "out")
    np.testing.assert_array_equal(n_got, n_ref)
    np.testing.assert_array_equal(a_got, a_ref)


def test_a_png_cut_short_is_named_damaged_with_what_to_do(
    inputs: dict[str, Path], tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """A PNG cut short (a full card, an interrupted copy) had been told only "cannot read
    image X", after libpng's own "Read Error" line."""
    acq = tmp_path / "acq"
    acq.mkdir()
    entries = []
    for e in read_lp(inputs["tiff"] / "lights.lp"):
        stem = Path(e.name).stem
        px = tifffile.imread(inputs["tiff"] / "linear" / f"{stem}.tif")
        cv2.imwrite(str(acq / f"{stem}.png"), px[..., ::-1])
        entries.append(LpEntry(f"{stem}.png", e.direction))
    write_lp(acq / "acquisition.lp", entries)
    victim = acq / entries[2].name
    victim.write_bytes(victim.read_bytes()[:3000])
    capfd.readouterr()
    r = runner.invoke(app, ["fit", str(acq / "acquisition.lp"), "--out", str(tmp_path / "o"), *FIT])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"{victim.name} is a damaged PNG: it ends before its IEND chunk (cut short)" in said
    assert "copy it again from the camera or card" in said
    assert "libpng" not in capfd.readouterr().err


def test_an_acquisition_mixing_8_and_16_bit_images_is_fitted_with_a_note(tmp_path: Path) -> None:
    """8-bit images are decoded as sRGB and 16-bit ones taken as linear (both documented); an
    acquisition mixing them (a 16-bit export beside JPEGs) was fitted without a word, though a
    gamma-encoded 16-bit export is then fitted wrongly. It is fitted, and said; an acquisition
    of one kind gets no such note."""
    from rti_rig.app.usecases.fit import load_acquisition

    src = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"
    acq = tmp_path / "acq"
    shutil.copytree(src, acq)
    notes: list[str] = []
    load_acquisition(acq / "dirs.lp", notes)
    assert not any("mixes" in n for n in notes)
    lp = (acq / "dirs.lp").read_text()
    first = lp.splitlines()[1].split()[0]  # image01.jpg
    rgb = cv2.imread(str(acq / first))[..., ::-1]
    write_linear_tiff(acq / "image01.tif", rgb.astype(np.uint16) * 257)  # a 16-bit export
    (acq / "dirs.lp").write_text(lp.replace(first, "image01.tif"))
    notes = []
    load_acquisition(acq / "dirs.lp", notes)
    mixed = [n for n in notes if "mixes" in n]
    assert len(mixed) == 1, notes
    assert "17 8-bit image(s), decoded as sRGB, with 1 16-bit one(s), taken as linear" in mixed[0]
    assert "image01.tif" in mixed[0] and "export every image of the acquisition alike" in mixed[0]


def _srgb8_to_linear16(srgb: np.ndarray) -> np.ndarray:
    """IEC 61966-2-1's sRGB decoding of 8-bit codes, at 16 bits (what a linear export holds)."""
    c = srgb.astype(np.float64) / 255.0
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return np.round(linear * 65535.0).astype(np.uint16)


def test_jpegs_beside_compressed_16_bit_exports_are_fitted_with_the_note(tmp_path: Path) -> None:
    """16-bit PNGs (compressed: decoded, not read in place) among JPEGs, the first of them
    listed first: the fit had refused the acquisition as "images of … differ: image05.png is
    (40, 48, 3) uint16, image01.png is (40, 48, 3) uint8" (one store of the first image's
    type), where an uncompressed 16-bit TIFF among them is fitted with a note. Both are
    fitted and said; each PNG holds its JPEG's pixels as linear data, so the normals are the
    all-JPEG fit's."""
    src = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"
    acq = tmp_path / "acq"
    shutil.copytree(src, acq)
    lp = acq / "dirs.lp"
    reference = tmp_path / "jpeg"
    _fit(lp, reference)
    text = lp.read_text()
    for name in ("image01.jpg", "image25.jpg"):  # the first listed, and one among the others
        srgb = cv2.imread(str(acq / name))
        png = name.replace(".jpg", ".png")
        assert cv2.imwrite(str(acq / png), _srgb8_to_linear16(srgb))
        text = text.replace(name, png)
    lp.write_text(text)
    out = tmp_path / "mixed"
    r = runner.invoke(app, ["fit", str(lp), "--out", str(out), *FIT])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "uint" not in said and "(395" not in said
    assert "mixes 16 8-bit image(s), decoded as sRGB, with 2 16-bit one(s)" in said
    assert "image01.png, image25.png" in said
    normals, jpeg_normals = np.load(out / "normals.npy"), np.load(reference / "normals.npy")
    lit = np.isfinite(jpeg_normals).all(axis=-1) & np.isfinite(normals).all(axis=-1)
    assert lit.mean() > 0.9
    assert np.percentile(_angles(normals[lit], jpeg_normals[lit]), 99) < 0.5
