"""A whole TIFF whose image data is damaged, saved into the watched folder of the shipped
folder-watch dome (its framed board emulated on a pty, the camera and its tethering program a
thread that saves a file for each shutter pulse the board saw): ``rti-rig run`` names the file
at once, with what to do.

Its decode had waited ``timeout_s`` for the file to change, as for one still being written, and
then advised raising ``stable_polls`` or ``poll_interval_s``: advice that cannot help a file
whose every byte its TIFF structure names is written and steady.
"""

from __future__ import annotations

import sys
import threading
from pathlib import Path

import numpy as np
import pytest
import tifffile
from conftest import folder_watch_config, refused_and_waited, tethered_run

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

#: long enough that a decode that waits for the file to change is told from one that does not
#: by what the run says (the waiting one says "did not change within 20 s")
TIMEOUT_S = 20.0


def _damaged_tiff(scratch: Path) -> bytes:
    """A 16-bit LZW TIFF whose header and structure are whole and whose strip is damaged."""
    tifffile.imwrite(
        scratch, np.full((64, 64, 3), 30000, np.uint16), photometric="rgb", compression="lzw"
    )
    with tifffile.TiffFile(scratch) as tif:
        offset, count = tif.pages[0].dataoffsets[0], tif.pages[0].databytecounts[0]
    data = scratch.read_bytes()
    scratch.unlink()
    return (
        data[:offset]
        + bytes(b ^ 0x5A for b in data[offset : offset + count])
        + data[offset + count :]
    )


def _config(tmp_path: Path, tether: Path) -> Path:
    """The shipped config with its folder set to ``tether``, watched for TIFFs."""
    return folder_watch_config(tmp_path, tether, timeout_s=TIMEOUT_S, tiffs=True)


def test_run_names_a_damaged_tiff_at_once_with_what_to_do(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    tether = tmp_path / "tether"
    tether.mkdir()
    out = tmp_path / "s"
    cfg = _config(tmp_path, tether)
    data = _damaged_tiff(tmp_path / "scratch.tif")
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, [("IMG_0001.tif", data)], out)
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert "IMG_0001.tif is a damaged TIFF" in said and "waiting will not help" in said, said
    assert f"cannot read image file {tether / 'IMG_0001.tif'} (" in said, said
    assert ".incoming" not in said, said  # the folder's file is named, not the session's copy
    assert f"left in {tether}" in said and "Save the shot again" in said, said
    assert f"did not change within {TIMEOUT_S:g} s" not in said, said
    assert (tether / "IMG_0001.tif").read_bytes() == data  # left as the program saved it
    assert lit_at_end == []  # the dome was switched off


class PausedCopy(threading.Thread):
    """A copy (cp, rsync, SMB, a Wi-Fi upload) of libtiff TIFFs into the folder, of a camera
    fired by someone else (``trigger = "none"``): once the board's first LED is lit half of
    ``IMG_0001.tif`` comes (libtiff writes its IFD last,
    so none of it), and the rest only once the camera waits for it after reading that half
    (until the run ends otherwise); each later
    light's file comes whole."""

    def __init__(self, firmware, folder: Path, data: bytes, tried: threading.Event) -> None:  # type: ignore[no-untyped-def]
        super().__init__(daemon=True)
        self.firmware, self.folder, self.data, self.tried = firmware, folder, data, tried
        self.stop = threading.Event()

    def run(self) -> None:
        saved = 0
        while not self.stop.is_set():
            pulses = sum(e.what == "lit" for e in list(self.firmware.history))
            if pulses > saved:
                saved += 1
                target = self.folder / f"IMG_{saved:04d}.tif"
                if saved == 1:
                    target.write_bytes(self.data[: len(self.data) // 2])
                    while not self.tried.wait(0.05):
                        if self.stop.is_set():
                            return
                target.write_bytes(self.data)
            self.stop.wait(0.02)


def test_run_waits_for_a_libtiff_tiff_whose_copy_paused_and_records_it_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Half a TIFF OpenCV (libtiff) wrote, of a camera fired by someone else, its IFD
    (written last) not yet copied: tifffile reads it as an image of no pixels. ``rti-rig
    run`` had stopped at once calling it 'a damaged TIFF'; it now waits for the rest and
    records the shot."""
    import cv2

    tether = tmp_path / "tether"
    tether.mkdir()
    out = tmp_path / "s"
    cfg = _config(tmp_path, tether)
    text = cfg.read_text(encoding="utf-8")
    assert 'trigger = "dome_shutter"' in text
    cfg.write_text(text.replace('trigger = "dome_shutter"', 'trigger = "none"'), encoding="utf-8")
    ok, encoded = cv2.imencode(".tif", np.full((64, 64, 3), 30000, np.uint16))
    assert ok
    # set once the half file was read, refused and is waited for: the copy may go on
    tried = refused_and_waited(monkeypatch)
    r, said, lit_at_end = tethered_run(
        monkeypatch,
        cfg,
        tether,
        [],
        out,
        camera=lambda firmware: PausedCopy(firmware, tether, encoded.tobytes(), tried),
    )
    assert "damaged" not in said and "Traceback" not in said, said
    assert tried.is_set(), said  # the half file was read and waited for
    assert r.exit_code == 0, said
    assert (out / "raw" / "image_001.tif").read_bytes() == encoded.tobytes()  # whole
    assert (out / "linear" / "image_002.tif").exists()
    assert lit_at_end == []


def _garbage_ifd_tiff(scratch: Path, kind: str) -> bytes:
    """A whole 16-bit TIFF whose first IFD is garbage of ``kind``: its tag count's bytes
    XORed, as a copy gone wrong leaves them ("xored"), or its header's offset moved onto a
    black pixel's zero red inside the pixel data, lit pixels after it ("zero in the data")."""
    pixels = np.full((64, 64, 3), 30000, np.uint16)
    pixels[20, 20, 0] = 0
    tifffile.imwrite(scratch, pixels, photometric="rgb")
    data = scratch.read_bytes()
    scratch.unlink()
    ifd = int.from_bytes(data[4:8], "little")
    assert 8 <= ifd < len(data)
    if kind == "zero in the data":
        at = data.index(bytes(2) + (30000).to_bytes(2, "little") * 2, ifd + 64)
        return data[:4] + at.to_bytes(4, "little") + data[8:]
    return data[:ifd] + bytes(b ^ 0x5A for b in data[ifd : ifd + 2]) + data[ifd + 2 :]


@pytest.mark.parametrize("kind", ["xored", "zero in the data"])
def test_run_names_a_tiff_whose_first_ifd_is_garbage_at_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kind: str
) -> None:
    """A whole TIFF, its size steady, whose header names a first IFD inside the file that
    holds a tag count no writer writes (tifffile: "suspicious number of tags"), or a count of
    0 (no finished IFD has one) with written bytes after it: ``rti-rig run`` had waited
    ``timeout_s`` (its capture-time read, then its decode), then advised raising
    stable_polls. A writer on its way leaves that slot zeros throughout (tifffile) or names
    no IFD yet (libtiff): the file is named at once as damaged, with what to do."""
    tether = tmp_path / "tether"
    tether.mkdir()
    out = tmp_path / "s"
    cfg = _config(tmp_path, tether)
    data = _garbage_ifd_tiff(tmp_path / "scratch.tif", kind)
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, [("IMG_0001.tif", data)], out)
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert "IMG_0001.tif is a damaged TIFF" in said and "waiting will not help" in said, said
    assert "first IFD" in said and "tag count" in said, said
    assert f"cannot read image file {tether / 'IMG_0001.tif'} (" in said, said
    assert f"left in {tether}" in said and "Save the shot again" in said, said
    assert f"did not change within {TIMEOUT_S:g} s" not in said, said
    assert "complete TIFF" not in said, said
    assert (tether / "IMG_0001.tif").read_bytes() == data  # left as the program saved it
    assert lit_at_end == []  # the dome was switched off


def test_run_names_a_raw_cut_short_with_libraws_words_as_text(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    """Half a DNG saved into the shipped folder-watch dome's folder, the rest never coming:
    ``rti-rig run`` names the folder's file (not the session's copy it decoded) and LibRaw's
    error with its words as text. The sentence had been LibRaw's refusal of the copy with the
    copy's path replaced inside it, LibRaw's words shown as a Python bytes literal
    ("(LibRawIOError: b'Input/output error')"). LibRaw's own line, printed by its C code on
    fd 2 ("<s>/raw/.incoming/IMG_0001.dng: Unexpected end of file", once for each read), had
    reached the terminal naming the session's hidden copy: its words are in the refusal."""
    from rti_rig.drivers.cameras.dng_writer import linear_to_mosaic, write_dng

    tether = tmp_path / "tether"
    tether.mkdir()
    out = tmp_path / "s"
    # the cut file waited for, then refused
    cfg = folder_watch_config(tmp_path, tether, timeout_s=1.5)
    whole = tmp_path / "whole.dng"
    mosaic = linear_to_mosaic(np.full((32, 32), 0.3), "RGGB", 256, 4095)
    write_dng(whole, mosaic, black_level=256, white_level=4095, exposure_s=0.5, iso=100)
    data = whole.read_bytes()[: whole.stat().st_size // 2]
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, [("IMG_0001.dng", data)], out)
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert f"{tether / 'IMG_0001.dng'}: LibRaw cannot decode this file (LibRawIOError: " in said
    assert "(LibRawIOError: Input/output error)" in said, said
    assert "b'" not in said and ".incoming" not in said, said
    assert "IMG_0001.dng did not change within 1.5 s" in said, said
    assert "Input/output error): LibRaw reports unexpected end of file; is it a " in said, said
    terminal = capfd.readouterr().err  # what C code wrote to fd 2, past the runner's capture
    assert ".incoming" not in terminal and "Unexpected end of file" not in terminal, terminal
    assert (tether / "IMG_0001.dng").read_bytes() == data  # left as the program saved it
    assert lit_at_end == []  # the dome was switched off
