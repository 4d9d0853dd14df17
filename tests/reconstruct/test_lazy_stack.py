"""The acquisition as a lazily read dask array: nothing read until asked, only the bands asked,
values exactly those of ImageStack.rows, a graph that carries no pixels."""

from __future__ import annotations

import pickle
import threading
from pathlib import Path

import numpy as np
import pytest

from rti_rig.core.image_files import write_linear_tiff
from rti_rig.core.tiff_rows import TiffRows
from rti_rig.reconstruct.lazy_stack import ImageReadError, StackSource, lazy_stack
from rti_rig.reconstruct.stack import ImageStack
from rti_rig.reconstruct.tiling import row_tiles

#: (file name, start row, stop row) of every read through CountingRows, and files opened
READS: list[tuple[str, int, int]] = []
OPENED: list[str] = []
_LOCK = threading.Lock()


class CountingRows(TiffRows):
    """TiffRows that records every band of rows read."""

    def __getitem__(self, key):  # type: ignore[override]
        start, stop, _ = key.indices(self.shape[0])
        with _LOCK:
            READS.append((self.path.name, start, stop))
        return super().__getitem__(key)


def counting_opener(path: Path) -> CountingRows:
    with _LOCK:
        OPENED.append(path.name)
    return CountingRows(path)


@pytest.fixture()
def files(tmp_path: Path) -> tuple[list[Path], np.ndarray]:
    rng = np.random.default_rng(3)
    pixels = rng.integers(0, 65536, size=(5, 41, 23, 3), dtype=np.uint16)
    paths = []
    for i, px in enumerate(pixels):
        paths.append(tmp_path / f"im{i}.tif")
        write_linear_tiff(paths[-1], px)
    READS.clear()
    OPENED.clear()
    return paths, pixels


def test_nothing_is_read_until_a_chunk_is_computed_then_only_its_rows(files) -> None:
    paths, _pixels = files
    stack = ImageStack([TiffRows(p) for p in paths])
    array = lazy_stack(StackSource.of(paths, stack, counting_opener), tile_rows=7)
    assert array.shape == (5, 41, 23, 3) and array.dtype == np.float32
    assert array.chunks[1] == tuple(s.stop - s.start for s in row_tiles(41, 7))
    assert READS == [] and OPENED == []  # making the array reads nothing
    got = array[:, 14:21].compute(scheduler="threads")  # exactly the third chunk
    np.testing.assert_array_equal(got, stack.rows(slice(14, 21), strict=False))
    assert sorted(OPENED) == sorted(p.name for p in paths)  # opened once per process
    assert {(a, b) for _, a, b in READS} == {(14, 21)}
    assert sorted(name for name, _, _ in READS) == sorted(p.name for p in paths)


def test_a_slice_across_chunks_reads_only_the_chunks_it_touches(files) -> None:
    paths, pixels = files
    stack = ImageStack([TiffRows(p) for p in paths])
    array = lazy_stack(StackSource.of(paths, stack, counting_opener), tile_rows=7)
    got = array[1:3, 10:16, 2:9].compute(scheduler="threads")
    expected = pixels[1:3, 10:16, 2:9].astype(np.float32) * np.float32(1 / 65535)
    np.testing.assert_array_equal(got, expected)
    # a chunk is a band of all lights: the two chunks the slice touches, once each, no more
    for _, start, stop in READS:
        assert start >= 7 and stop <= 21, (start, stop)  # within chunks 7:14 and 14:21
    assert sum(stop - start for _, start, stop in READS) <= len(paths) * 14


def test_every_chunk_equals_the_single_process_band(files) -> None:
    paths, _ = files
    stack = ImageStack([TiffRows(p) for p in paths])
    array = lazy_stack(StackSource.of(paths, stack, TiffRows), tile_rows=9)
    blocks = array.to_delayed().ravel()
    import dask

    computed = dask.compute(*blocks, scheduler="threads")
    for sl, block in zip(row_tiles(41, 9), computed, strict=True):
        ref = stack.rows(sl, strict=False)
        assert block.dtype == ref.dtype and block.shape == ref.shape
        assert block.tobytes() == ref.tobytes()


def test_the_graph_carries_paths_not_pixels(files) -> None:
    paths, pixels = files
    stack = ImageStack([TiffRows(p) for p in paths])
    source = StackSource.of(paths, stack, TiffRows)
    assert len(pickle.dumps(source)) < 4096 < pixels.nbytes
    array = lazy_stack(source, tile_rows=7)
    assert len(pickle.dumps(dict(array.__dask_graph__()))) < 16384


def test_an_unreadable_file_is_named_with_the_host(files) -> None:
    paths, _ = files
    stack = ImageStack([TiffRows(p) for p in paths])
    array = lazy_stack(StackSource.of(paths, stack, TiffRows), tile_rows=7)
    paths[2].unlink()
    with pytest.raises(ImageReadError, match=r"im2\.tif on host"):
        array[:, :7].compute(scheduler="sync")


def test_a_file_of_another_shape_is_refused(files) -> None:
    paths, _ = files
    stack = ImageStack([TiffRows(p) for p in paths])
    array = lazy_stack(StackSource.of(paths, stack, TiffRows), tile_rows=7)
    paths[1].unlink()
    write_linear_tiff(paths[1], np.zeros((40, 23, 3), np.uint16))
    with pytest.raises(ImageReadError, match=r"im1\.tif .*shape"):
        array[:, :7].compute(scheduler="sync")


def test_a_file_rewritten_at_the_same_path_is_read_again(tmp_path: Path) -> None:
    """A long-lived worker keeps opened acquisitions (decoded pixels, for images that cannot be
    read by rows); one rewritten since at the same path (a re-exported PNG) must be read again,
    not served from the cache."""
    import os

    import cv2

    from rti_rig.app.usecases.fit import read_image

    rng = np.random.default_rng(5)
    paths = [tmp_path / f"im{i}.png" for i in range(3)]

    def write(level: int) -> None:
        for p in paths:
            img = np.clip(rng.normal(level, 3, (20, 16, 3)), 0, 255).astype(np.uint8)
            old = p.stat().st_mtime_ns if p.exists() else None
            cv2.imwrite(str(p), img)
            if old is not None:  # a later stamp even on a coarse file-system clock
                os.utime(p, ns=(old + 10**9, old + 10**9))

    def mean() -> float:
        stack = ImageStack([read_image(p) for p in paths])
        source = StackSource.of(paths, stack, read_image)
        return float(lazy_stack(source, tile_rows=7).compute(scheduler="threads").mean())

    write(20)
    dark = mean()
    write(200)
    assert mean() > 10 * dark
