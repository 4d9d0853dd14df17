"""A fit output the fit could not write is named as a word that pastes into a shell, in a folder
whose name is not UTF-8 (an archive unpacked with its Windows names) as anywhere.

The normal map, the albedo map and the QA coverage map, which OpenCV writes (saying a failure only
by its return value), had been named with Python's lone surrogate (``caf\\udce9``, which no shell
reads back), as had the file in the refusal of an output the disk would not hold.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

import cv2
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.shell_words import shown_path
from rti_rig.reconstruct import exporters


@pytest.fixture
def acquisition(not_utf8_acquisition: Path) -> Path:
    """Six small grey JPEGs and their .lp, in a folder whose name is not UTF-8."""
    return not_utf8_acquisition


def _fit(acquisition: Path, *qa: str) -> tuple[int, str]:
    out = acquisition.parent / "fit"
    args = ["fit", str(acquisition), "--out", str(out), "--model", "ps", *qa]
    r = CliRunner().invoke(app, args, terminal_width=400)
    return r.exit_code, " ".join(r.output.split())


@pytest.mark.parametrize("png", ["normals.png", "albedo.png", "qa_coverage.png"])
def test_a_map_opencv_did_not_write_is_named_as_a_word_that_pastes(
    acquisition: Path, monkeypatch: pytest.MonkeyPatch, png: str
) -> None:
    real = cv2.imwrite

    def refused(path: bytes, img, *args):  # type: ignore[no-untyped-def]
        return False if os.fsdecode(path).endswith(png) else real(path, img, *args)

    monkeypatch.setattr(cv2, "imwrite", refused)
    code, said = _fit(acquisition, *([] if png == "qa_coverage.png" else ["--no-qa"]))
    assert code != 0, said
    assert f"could not write {shown_path(acquisition.parent / 'fit' / png)}: " in said, said
    assert "check the free space and that the folder is writable" in said, said
    assert "\udce9" not in said and "Traceback" not in said, said


def test_the_file_the_disk_would_not_hold_is_named_as_a_word_that_pastes(
    acquisition: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def full(stem: Path, *args, **kwargs):  # type: ignore[no-untyped-def]
        raise OSError(errno.ENOSPC, "No space left on device", str(stem.with_suffix(".png")))

    monkeypatch.setattr(exporters, "write_normal_map", full)
    code, said = _fit(acquisition, "--no-qa")
    assert code != 0, said
    shown = shown_path(acquisition.parent / "fit" / "normals.png")
    assert f"({shown}): No space left on device" in said, said
    assert "\udce9" not in said and "Traceback" not in said, said
