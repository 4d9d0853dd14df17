"""A DNG a network share writes size-first (SMB, some NAS clients: the file's final size set
at once, its bytes filled afterwards, not always in order), saved into the watched folder of
the shipped folder-watch dome (its framed board emulated on a pty, the camera and its
tethering program a thread): ``rti-rig run`` waits for its IFD to be filled and settle before
judging its structure, and still refuses, naming it, one whose IFD stays unwritten.

Why: the folder watch refused a DNG at once when its CFAPattern or StripOffsets entry was
missing (LibRaw would read such a file with a pattern, or pixels, of its own guessing). In a
file still arriving those entries are zeros for a while: a good shot had been refused as
damaged, its light lost, though its bytes came a moment later.

The tethering thread fills the missing bytes only once the decoder has read the file's tags
and found them missing (a spy on ``read_blind`` sets an event): no timing is assumed.
"""

from __future__ import annotations

import struct
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from conftest import folder_watch_config, tethered_run
from dng_spec_writer import dng

from rti_rig.drivers.cameras import raw_decode

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

#: how long the tethering thread waits for the decoder to have looked (generous: 2 cores)
_PATIENCE_S = 60.0


def _entry(data: bytes, tag: int) -> int:
    """The byte offset of ``tag``'s entry in the (little-endian, IFD at 8) DNG's IFD 0."""
    for n in range(struct.unpack_from("<H", data, 8)[0]):
        at = 10 + 12 * n
        if struct.unpack_from("<H", data, at)[0] == tag:
            return at
    raise AssertionError(f"no tag {tag}")


class SizeFirstShare(threading.Thread):
    """A tethering program copying over a share that sets the size first: at the board's
    first shutter pulse the file appears at its full size, the entries of ``late`` (tags) still
    zeros; the rest is filled once ``looked`` is set (unless ``never_filled``)."""

    def __init__(
        self,
        firmware: object,
        path: Path,
        data: bytes,
        late: tuple[int, ...],
        looked: threading.Event,
        never_filled: bool = False,
    ) -> None:
        super().__init__(daemon=True)
        self.firmware, self.path, self.data, self.looked = firmware, path, data, looked
        self.slots = [_entry(data, tag) for tag in late]
        self.never_filled = never_filled
        self.stop = threading.Event()
        self.filled = threading.Event()

    def run(self) -> None:
        while not self.stop.is_set():
            if any(e.what == "shutter" for e in list(self.firmware.history)):  # type: ignore[attr-defined]
                break
            self.stop.wait(0.02)
        else:
            return
        first = bytearray(self.data)
        for at in self.slots:
            first[at : at + 12] = bytes(12)
        with self.path.open("wb") as f:
            f.truncate(len(self.data))  # the size, set first
            f.write(first)  # all but the late entries
        if self.never_filled:
            return
        if not self.looked.wait(_PATIENCE_S) or self.stop.is_set():
            return
        with self.path.open("r+b") as f:
            for at in self.slots:
                f.seek(at)
                f.write(self.data[at : at + 12])
        self.filled.set()


def _run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, late: tuple[int, ...], **kw: object
) -> tuple[object, str, bytes, Path, SizeFirstShare, list[int]]:
    tether = tmp_path / "tether"
    tether.mkdir()
    out = tmp_path / "s"
    never = bool(kw.pop("never_filled", False))
    cfg = folder_watch_config(tmp_path, tether, **kw)  # type: ignore[arg-type]
    data = dng(np.full((32, 48), 20000, np.uint16))
    looked = threading.Event()
    real = raw_decode.read_blind

    def spy(path: Path) -> str | None:
        said = real(path)
        if said is not None:
            looked.set()  # the decoder read the tags and found an entry missing
        return said

    monkeypatch.setattr(raw_decode, "read_blind", spy)
    shares: list[SizeFirstShare] = []

    def share_on(firmware: object) -> SizeFirstShare:
        shares.append(SizeFirstShare(firmware, tether / "IMG_0001.dng", data, late, looked, never))
        return shares[-1]

    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, [], out, share_on, lights=1)
    assert looked.is_set()  # the file was read while its entries were zeros
    return r, said, data, out, shares[0], lit_at_end


@pytest.mark.parametrize(
    "late", [(33421, 33422), (273,)], ids=["cfa entries late", "strip offsets late"]
)
def test_run_takes_a_dng_whose_ifd_a_share_fills_after_its_size(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, late: tuple[int, ...]
) -> None:
    r, said, data, out, share, lit_at_end = _run(tmp_path, monkeypatch, late, timeout_s=60.0)
    assert share.filled.is_set()
    assert r.exit_code == 0, said
    assert "damaged" not in said, said
    kept = list((out / "raw").glob("*.dng"))
    assert len(kept) == 1 and kept[0].read_bytes() == data, said  # the whole shot, kept
    assert len(list((out / "linear").glob("image_*.tif"))) == 1, said
    assert lit_at_end == []


def test_run_refuses_a_dng_whose_ifd_stays_unwritten_naming_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    r, said, _, out, _, lit_at_end = _run(
        tmp_path, monkeypatch, (33421, 33422), timeout_s=5.0, never_filled=True
    )
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert f"{tether_file(tmp_path)}: " in said, said  # the folder's file, not the copy
    assert "gives no CFARepeatPatternDim or CFAPattern" in said, said
    assert "parts of its IFD are still zeros" in said, said
    assert "IMG_0001.dng did not change within 5 s" in said, said
    assert tether_file(tmp_path).is_file()  # left where the program saved it
    assert not list((out / "linear").glob("image_*.tif")), said
    assert lit_at_end == []


def tether_file(tmp_path: Path) -> Path:
    return tmp_path / "tether" / "IMG_0001.dng"


def test_run_refuses_a_dng_whose_ifd_never_settles_within_timeout_naming_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A file whose IFD is rewritten between every two polls (a program saving it over and
    over) is never judged whole, and is refused within ``timeout_s``, naming it."""
    from rti_rig.drivers.cameras import folder_watch

    real = folder_watch.ifd_state
    tick = [0]

    def rewritten_between_polls(path: Path) -> object:
        state = real(path)
        if path.parent.name == "tether":  # the folder's file, rewritten after each look
            with path.open("r+b") as f:
                f.seek(_entry(path.read_bytes(), 274) + 8)  # Orientation's value, in place
                tick[0] += 1
                f.write(struct.pack("<H", 1 + 2 * (tick[0] % 2)))
        return state

    monkeypatch.setattr(folder_watch, "ifd_state", rewritten_between_polls)
    r, said, _, out, _, lit_at_end = _run(
        tmp_path, monkeypatch, (33421, 33422), timeout_s=5.0, never_filled=True
    )
    assert tick[0] >= 2  # looked at more than once
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert f"{tether_file(tmp_path)}: " in said, said
    assert "IMG_0001.dng was still being written 5 s after that" in said, said
    assert "waiting will not help" not in said, said  # never judged whole
    assert not list((out / "linear").glob("image_*.tif")), said
    assert lit_at_end == []
