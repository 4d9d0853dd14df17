"""Paths handed to OpenCV: an ordinary name as the str every OpenCV takes, a name whose bytes
are not UTF-8 as its bytes, read and written by Python where this OpenCV refuses bytes.

Why: given every path as bytes, OpenCV 4.8 (which pyproject allows) refused them all
(``TypeError: Can't convert object to 'str' for 'filename'``): no image read or written.
The refusal is modelled as OpenCV 4.8's binding raises it (imread: TypeError; the overloaded
imwrite: cv2.error), checked against 4.8.1 itself.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from rti_rig.core import opencv_files
from rti_rig.core.image_files import read_image_any

NOT_UTF8 = os.fsdecode(b"caf\xe9")


@pytest.fixture
def no_bytes(monkeypatch: pytest.MonkeyPatch) -> None:
    """cv2.imread and cv2.imwrite as OpenCV 4.8's binding: a bytes name refused."""
    real_read, real_write = cv2.imread, cv2.imwrite

    def imread(name: Any, *args: Any) -> Any:
        if not isinstance(name, str):
            raise TypeError("Can't convert object to 'str' for 'filename'")
        return real_read(name, *args)

    def imwrite(name: Any, *args: Any) -> Any:
        if not isinstance(name, str):
            raise cv2.error("Overload resolution failed")
        return real_write(name, *args)

    monkeypatch.setattr(cv2, "imread", imread)
    monkeypatch.setattr(cv2, "imwrite", imwrite)


def _image() -> np.ndarray:
    return np.arange(12 * 16 * 3, dtype=np.uint16).reshape(12, 16, 3) * 7


def test_an_ordinary_name_is_read_by_an_opencv_that_takes_no_bytes(
    tmp_path: Path, no_bytes: None
) -> None:
    """Given as bytes, every image read had failed there: fit, run's replay and plan alike."""
    png = tmp_path / "img 1.png"
    assert cv2.imwrite(str(png), _image())
    assert np.array_equal(read_image_any(png), _image()[..., ::-1])
    assert opencv_files.imwrite(tmp_path / "img 2.png", _image())
    assert np.array_equal(cv2.imread(str(tmp_path / "img 2.png"), -1), _image())


@pytest.mark.parametrize("takes_bytes", [True, False])
def test_a_name_not_utf8_is_written_and_read_back(
    tmp_path: Path, request: pytest.FixtureRequest, takes_bytes: bool
) -> None:
    if not takes_bytes:
        request.getfixturevalue("no_bytes")
    folder = tmp_path / NOT_UTF8
    folder.mkdir()
    png = folder / "img.png"
    assert opencv_files.opencv_name(png) == os.fsencode(png)
    assert opencv_files.imwrite(png, _image())
    assert np.array_equal(opencv_files.imread(png), _image())
    assert opencv_files.imread(folder / "missing.png") is None
    assert not opencv_files.imwrite(folder / "none" / "img.png", _image())


def test_a_map_that_could_not_be_written_is_named_as_a_shell_reads_it(tmp_path: Path) -> None:
    """``could not write`` named the file by Python's str of it: in a folder whose name is not
    UTF-8, ``caf\\udce9/...``, which no shell reads back; it goes through shown_path now."""
    from rti_rig.core.shell_words import shown_path
    from rti_rig.reconstruct.errors import ReconstructionError
    from rti_rig.reconstruct.exporters import write_albedo, write_normal_map

    gone = tmp_path / NOT_UTF8 / "fit"  # no such folder: OpenCV's write fails
    normals = np.zeros((4, 5, 3), np.float32)
    for write in (write_normal_map, write_albedo):
        with pytest.raises(ReconstructionError) as refused:
            write(gone / "map", normals)
        assert f"could not write {shown_path(gone / 'map.png')}" in str(refused.value)
        assert "\udce9" not in str(refused.value)
