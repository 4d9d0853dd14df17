"""`rti-rig fit` within relight's memory (issue #29): what keeps it there, checked through the
CLI — images and maps never mapped into memory, outputs that do not depend on the band size, a
decode into reused buffers that still refuses a broken image, and a fit that imports no plotting
or learning library. The memory figure itself is measured by ``benchmarks/fit_session.py``."""

from __future__ import annotations

import mmap
import os
import shutil
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
import tifffile
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import linear_to_srgb8
from rti_rig.core.lp_format import LpEntry, read_lp, write_lp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

runner = CliRunner()
NORMALS = ["--model", "ps", "--no-qa", "--no-ptm", "--no-hsh"]


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A simulated session (uncompressed TIFFs) and the same images as sRGB JPEGs + .lp."""
    root = tmp_path_factory.mktemp("inputs")
    session, _, _ = make_session(root / "tiff", size=(64, 80))
    jpeg = root / "jpeg"
    jpeg.mkdir()
    entries = []
    for e in read_lp(session / "lights.lp"):
        stem = Path(e.name).stem
        px = tifffile.imread(session / "linear" / f"{stem}.tif")
        srgb = linear_to_srgb8(px, 65535)
        cv2.imwrite(str(jpeg / f"{stem}.jpg"), srgb[..., ::-1], [cv2.IMWRITE_JPEG_QUALITY, 95])
        entries.append(LpEntry(f"{stem}.jpg", e.direction))
    write_lp(jpeg / "lights.lp", entries)
    return {"tiff": session, "jpeg": jpeg}


def _fit(source: Path, out: Path, *args: str) -> None:
    r = runner.invoke(app, ["fit", str(source), "--out", str(out), *args])
    assert r.exit_code == 0, r.output


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


@pytest.mark.parametrize("kind", ["tiff", "jpeg"])
def test_the_fit_maps_no_image_and_writes_no_map_through_memory(
    inputs: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kind: str
) -> None:
    """Pages of a file mapped into the process count in its resident memory: the fit reads
    images (and the temporary file JPEGs are decoded into) by ``pread``, writes its float maps
    by ``pwrite``, and maps nothing but the finished maps, read-only, to encode their PNGs."""
    mapped: list[tuple[str, int]] = []

    class RecordingMmap(mmap.mmap):
        def __new__(cls, fileno: int, length: int, *args: object, **kwargs: object):  # type: ignore[no-untyped-def]
            target = os.readlink(f"/proc/self/fd/{fileno}") if fileno >= 0 else "anonymous"
            mapped.append((target, int(kwargs.get("access", mmap.ACCESS_DEFAULT))))  # type: ignore[arg-type]
            return super().__new__(cls, fileno, length, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(mmap, "mmap", RecordingMmap)
    out = tmp_path / "out"
    _fit(inputs[kind], out, *NORMALS)
    assert (out / "normals.png").is_file() and (out / "albedo.png").is_file()
    names = sorted(Path(target).name for target, _ in mapped)
    assert names == ["albedo.npy", "normals.npy"], mapped
    assert all(access == mmap.ACCESS_READ for _, access in mapped), mapped


def test_the_outputs_do_not_depend_on_the_band_size(
    inputs: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The band budget is a memory knob (4 MB since the memory work of issue #29, 8 MB before):
    every output — maps, .ptm, .rti, QA — is byte for byte the same with bands of a few rows
    and with the whole image in one band."""
    import rti_rig.app.usecases.fit as fit

    results = []
    for budget in (3 * 36 * 80 * 4 * 3, 1 << 30):  # three rows per band; one band
        monkeypatch.setattr(fit, "BAND_BUDGET_BYTES", budget)
        out = tmp_path / f"out{budget}"
        _fit(inputs["jpeg"], out, "--model", "ps")
        results.append(_files(out))
    assert results[0].keys() == results[1].keys()
    assert {"normals.npy", "albedo.npy", "fit.ptm", "fit.rti", "qa.json"} <= results[0].keys()
    for name in results[0]:
        assert results[0][name] == results[1][name], name


def test_the_maps_written_by_bands_are_the_npy_files_numpy_writes(tmp_path: Path) -> None:
    """MapFile lays the file out with numpy's own header and fills it band by band: the result
    is the ``.npy`` that ``np.save`` writes of the whole map."""
    from rti_rig.app.usecases.fit_maps import MapFile

    rng = np.random.default_rng(3)
    whole = rng.standard_normal((37, 11, 3)).astype(np.float32)
    maps = MapFile(tmp_path / "bands.npy", whole.shape)
    for top in (0, 10, 20, 30):  # in order, and a short last band
        maps.write_rows(top, whole[top : top + 10])
    back = maps.read()
    np.save(tmp_path / "whole.npy", whole)
    assert (tmp_path / "bands.npy").read_bytes() == (tmp_path / "whole.npy").read_bytes()
    np.testing.assert_array_equal(back, whole)
    with pytest.raises(ValueError):
        maps.write_rows(0, whole[:2])  # closed by read()


def test_a_broken_jpeg_decoded_into_a_reused_buffer_is_refused_by_name(
    inputs: dict[str, Path], tmp_path: Path
) -> None:
    """From the second image on, JPEGs are decoded into a buffer that held the previous image;
    OpenCV then returns that buffer unchanged for a file it cannot decode. The fit must still
    refuse the file by name (exit code 2), never fit the previous image's pixels again."""
    acquisition = tmp_path / "jpeg"
    shutil.copytree(inputs["jpeg"], acquisition)
    victim = sorted(acquisition.glob("*.jpg"))[5]
    victim.write_bytes(b"\xff\xd8\xff\xe0 not the rest of a JPEG")
    r = runner.invoke(app, ["fit", str(acquisition), "--out", str(tmp_path / "out"), *NORMALS])
    assert r.exit_code == 2, r.output
    assert victim.name in said(r)


def test_decoding_into_a_buffer_gives_what_imread_gives(tmp_path: Path) -> None:
    """Into a buffer of the right shape: the same pixels as a plain ``cv2.imread`` (RGB), in
    the buffer; an image whose last row equals the canary (the complement of the buffer's last
    row) is decoded right, not taken for a failure; a file that does not decode is None."""
    from rti_rig.app.usecases.fit_decode import imread_rgb

    rng = np.random.default_rng(5)
    img = rng.integers(0, 256, (20, 24, 3), dtype=np.uint8)
    buffer = np.zeros_like(img)
    buffer[-1] = np.invert(img[-1])  # the canary written before decoding will be img[-1]
    path = tmp_path / "a.png"
    cv2.imwrite(str(path), img[..., ::-1])
    got = imread_rgb(path, buffer)
    assert got is not None
    np.testing.assert_array_equal(got, img)
    other = tmp_path / "b.png"
    cv2.imwrite(str(other), img[::-1, :, ::-1])
    got = imread_rgb(other, buffer)
    assert got is buffer
    np.testing.assert_array_equal(got, img[::-1])
    bad = tmp_path / "bad.jpg"
    bad.write_bytes(b"not an image")
    assert imread_rgb(bad, buffer) is None
    assert imread_rgb(bad) is None


def test_the_fit_imports_no_plotting_or_learning_library() -> None:
    """A normals fit's memory starts with what the process imported: the fit's use case and
    the CLI load none of matplotlib, scikit-learn, SciPy, onnxruntime, Dask (each 10–60 MB)."""
    heavy = ("matplotlib", "sklearn", "scipy", "onnxruntime", "dask", "distributed")
    code = (
        "import sys\n"
        "import rti_rig.cli, rti_rig.app.usecases.fit\n"
        f"print(sorted(m for m in {heavy!r} if m in sys.modules))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]", done.stdout


def test_the_heap_helpers_answer_on_glibc() -> None:
    """On glibc (Linux here) the arena cap and the trim are available and report success; they
    are no-ops (False) on other C libraries, where the fit's outputs are the same."""
    import platform

    from rti_rig.app.usecases.fit_memory import release_free_memory, use_one_heap

    if platform.libc_ver()[0] != "glibc":
        pytest.skip("glibc only")
    assert use_one_heap() is True
    freed = [np.ones(12_000) for _ in range(300)]  # 96 kB each: from the heap, not mmap
    kept = [np.ones(12_000) for _ in range(3)]  # above them: the heap's top is not free
    del freed
    assert release_free_memory() is True
    del kept


def test_only_the_command_caps_the_heap(
    inputs: dict[str, Path], tmp_path: Path, monkeypatch
) -> None:
    """The one-heap cap lasts for the whole process, so `rti-rig fit` sets it and the use case
    does not: a Dask worker or a test process that runs fits among other work keeps its
    allocator."""
    from rti_rig.app.usecases import fit_memory
    from rti_rig.app.usecases.fit import FitRequest, run_fit

    calls: list[str] = []
    monkeypatch.setattr(fit_memory, "use_one_heap", lambda: calls.append("cap") or True)
    run_fit(FitRequest(inputs["tiff"], tmp_path / "lib", model="ps", qa=False))
    assert calls == []
    _fit(inputs["tiff"], tmp_path / "cli", *NORMALS)
    assert calls == ["cap"]


def test_the_sample_keeps_its_size_up_to_100_rgb_lights_and_shrinks_beyond() -> None:
    """The fit's pixel sample is held whole (model choice, quantisation ranges, the QA's copy):
    at 30 000 pixels it grew with the lights (360 MB of float32 at 1000 RGB lights, peak RSS
    1.4 GB for a 128 × 128 fit). Up to 100 RGB images it is unchanged (the outputs too); beyond,
    it holds at most ``SAMPLE_VALUES`` values."""
    from rti_rig.reconstruct import signal_check as sc

    assert sc.sample_pixels(72, 3) == sc.sample_pixels(100, 3) == sc.SAMPLE_PIXELS
    assert sc.sample_pixels(300, 1) == sc.SAMPLE_PIXELS
    for n, c in ((301, 3), (1000, 3), (1000, 1), (2500, 3)):
        assert sc.sample_pixels(n, c) < sc.SAMPLE_PIXELS
        assert sc.sample_pixels(n, c) * n * c <= sc.SAMPLE_VALUES
    assert sc.sample_pixels(100_000, 3) == sc.MIN_SAMPLE_PIXELS


def test_the_fit_and_its_qa_hold_a_sample_within_the_budget(
    inputs: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Through the CLI, with the sample's budget lowered so that this small session's lights
    exceed it: every pixel sample the fit holds (model choice, quantisation ranges, HSH order)
    and the QA's grid stay within ``SAMPLE_VALUES`` values, and the QA samples the pixels the
    fit's signal check does (one grid for both)."""
    from rti_rig.reconstruct import qa, signal_check
    from rti_rig.reconstruct.stack import ImageStack

    n = len(read_lp(inputs["tiff"] / "lights.lp"))
    budget = n * 3 * 1500  # 1500 RGB pixels of this session's lights, of its 5120
    monkeypatch.setattr(signal_check, "SAMPLE_VALUES", budget, raising=False)
    held: list[int] = []
    grids: list[int] = []
    sample = ImageStack.pixel_sample

    def recording_sample(self: ImageStack, max_pixels: int) -> tuple[np.ndarray, np.ndarray]:
        values, flat = sample(self, max_pixels)
        if self.channels == 3:  # the fit's stack (the QA's crop fit is grey: its own sample)
            held.append(values.size)
        return values, flat

    grid = qa.sample_grid

    def recording_grid(height: int, width: int, max_pixels: int) -> tuple[np.ndarray, np.ndarray]:
        rows, cols = grid(height, width, max_pixels)
        grids.append(rows.size * cols.size)
        return rows, cols

    monkeypatch.setattr(ImageStack, "pixel_sample", recording_sample)
    monkeypatch.setattr(qa, "sample_grid", recording_grid)
    _fit(inputs["tiff"], tmp_path / "out")  # auto model, normals, .ptm, .rti, QA
    assert held and grids, (held, grids)
    assert max(held) <= budget, held
    assert all(g * n * 3 <= budget for g in grids), grids
    assert {h // (n * 3) for h in held} >= set(grids)
