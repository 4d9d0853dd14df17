"""A whole DNG that LibRaw refuses as "Unsupported file format or not RAW file" (or would
read, its CFAPattern lost, with a pattern of its own guessing, or its StripOffsets lost, with
pixels read from bytes that are not the picture's), saved into the watched folder
of the shipped folder-watch dome (its framed board emulated on a pty, the camera and its
tethering program a thread that saves the file at the first shutter pulse): ``rti-rig run``
says what the file's own tags show.

LibRaw gives that one error (LIBRAW_FILE_UNSUPPORTED) both for a DNG whose tags are damaged and
for one it cannot read because it is newer than LibRaw: every such file had been refused with
"a camera newer than this LibRaw … Update rawpy", advice that cannot mend a damaged file. A
DNG without CFAPattern had gone into the session as a picture of LibRaw's guessing (all red
photosites at one read, an IndexError at another), and one without StripOffsets as a picture of
bytes that are not its own, without a word. The DNGs here come from the tests' own DNG
writer (written from the TIFF and DNG specifications), each with one thing changed.
"""

from __future__ import annotations

import struct
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import folder_watch_config, tethered_run
from dng_spec_writer import dng

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def _entry(data: bytearray, tag: int) -> int:
    """The byte offset of ``tag``'s entry in the (little-endian, IFD at 8) DNG's IFD 0."""
    for n in range(struct.unpack_from("<H", data, 8)[0]):
        at = 10 + 12 * n
        if struct.unpack_from("<H", data, at)[0] == tag:
            return at
    raise AssertionError(f"no tag {tag}")


def _changed(how: str) -> bytes:
    data = bytearray(dng(np.full((32, 48), 20000, np.uint16)))
    if how == "width tag lost":  # ImageWidth's tag number damaged: its value is still there
        struct.pack_into("<H", data, _entry(data, 256), 250)
    elif how == "cfa pattern lost":  # decodes, with a pattern LibRaw guesses anew each read
        struct.pack_into("<H", data, _entry(data, 33422), 33000)
    elif how == "strip offsets lost":  # decodes, its pixels read from where LibRaw guesses
        struct.pack_into("<H", data, _entry(data, 273), 250)
    elif how == "jpeg xl":  # a DNG 1.7 compression this LibRaw build does not decode
        struct.pack_into("<H", data, _entry(data, 259) + 8, 52546)
    else:  # a compression code no DNG specification names: cannot be told from here
        assert how == "unknown compression"
        struct.pack_into("<H", data, _entry(data, 259) + 8, 99)
    return bytes(data)


@pytest.mark.parametrize(
    "how",
    ["width tag lost", "cfa pattern lost", "strip offsets lost", "jpeg xl", "unknown compression"],
)
def test_run_says_what_a_refused_dngs_own_tags_show(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, how: str
) -> None:
    tether = tmp_path / "tether"
    tether.mkdir()
    out = tmp_path / "s"
    cfg = folder_watch_config(tmp_path, tether)
    data = _changed(how)
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, [("IMG_0001.dng", data)], out)
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert f"{tether / 'IMG_0001.dng'}: " in said, said  # the folder's file, not the copy
    assert ".incoming" not in said, said
    assert "it names itself a DNG" in said, said
    if how not in ("cfa pattern lost", "strip offsets lost"):  # LibRaw's words: it refused
        assert "Unsupported file format or not RAW file" in said, said
    assert "a camera newer than this LibRaw" not in said, said
    assert "waiting will not help" in said and f"left in {tether}" in said, said
    if how == "width tag lost":
        assert "it is damaged (its main image gives no ImageWidth)" in said, said
        assert "updating rawpy will not help" in said, said
        assert "pip install -U rawpy" not in said, said
    elif how == "cfa pattern lost":
        assert "its main image, a CFA mosaic, gives no CFAPattern" in said, said
        assert "The file is damaged: copy the shot again" in said, said
        assert "did not change within" not in said, said  # not waited for
    elif how == "strip offsets lost":
        assert "its main image gives no StripOffsets or TileOffsets" in said, said
        assert "The file is damaged: copy the shot again" in said, said
        assert "did not change within" not in said, said  # not waited for
    elif how == "jpeg xl":
        assert "compressed as JPEG XL" in said and "pip install -U rawpy" in said, said
        assert "damaged" not in said, said
    else:
        assert "compression code 99" in said, said
        assert "either newer than this LibRaw reads or damaged" in said, said
        assert "if it opens, update rawpy" in said and "copy the shot again" in said, said
    assert not list((out / "linear").glob("image_*.tif")), said
    assert (tether / "IMG_0001.dng").read_bytes() == data  # left as the program saved it
    assert lit_at_end == []  # the dome was switched off
