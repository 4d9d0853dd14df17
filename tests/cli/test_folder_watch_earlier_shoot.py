"""A watched folder that holds an earlier shoot's files, and a camera whose file numbers start
again onto their names, through `rti-rig run` on the shipped folder-watch example (its dome
firmware emulated on a pty, its camera a thread that saves a DNG into the folder for each
shutter pulse the board saw).

A new or formatted card, a counter reset or the wrap from IMG_9999 to IMG_0001 has the
tethering program save this run's shots over the earlier shoot's ``IMG_0001.DNG`` …: in place
(the same file written again) or as a new file renamed over the old one. A name is used once,
so the shot is not taken, rightly; but the timeout said "an earlier shot had it" (none had)
and "have the tethering program give every shot its own file name" (it did), and a resume
stopped again at the next number: the fix, emptying the folder, was never said.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
from conftest import Tether, folder_watch_config, tethered_run
from dng_spec_writer import flat_dng

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


class RenamingTether(Tether):
    """A tethering program that saves each shot to a hidden temporary and renames it over
    the final name (a new file under the old name, as rsync and many programs save)."""

    def save(self, name: str, data: bytes) -> None:
        temporary = self.folder / f".{name}.tmp"
        temporary.write_bytes(data)
        os.replace(temporary, self.folder / name)


@pytest.mark.parametrize("saving", ["in place", "renamed over"])
def test_an_earlier_shoots_file_saved_over_is_said_with_the_folder_to_empty(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, saving: str
) -> None:
    tether = tmp_path / "tether"
    tether.mkdir()
    for k in range(1, 4):  # the earlier shoot
        (tether / f"IMG_{k:04d}.DNG").write_bytes(flat_dng(0.1) + b"earlier shoot")
    cfg = folder_watch_config(tmp_path, tether, timeout_s=10.0)
    files = [(f"IMG_{k:04d}.DNG", flat_dng(0.3)) for k in range(1, 4)]
    camera = (lambda fw: RenamingTether(fw, tether, files)) if saving == "renamed over" else None
    run = tethered_run(monkeypatch, cfg, tether, files, tmp_path / "s", camera=camera)
    said = run.said
    assert run.result.exit_code == 2, said
    assert "Traceback" not in said and not run.lit_at_end, said
    # the first words say what happened: this run's shot came and was set aside, and why
    assert said.split("error: ", 1)[1].startswith(
        "folder-camera during 'wait for file': IMG_0001.DNG came but was set aside, because "
        "its name was an earlier shoot's file's already in the folder; no other new file "
        "matching"
    ), said
    assert "IMG_0001.DNG was in the folder before this run began" in said, said
    assert "an earlier shot had it" not in said, said
    assert "give every shot its own file name" not in said, said
    assert f"move the files already in {tether} elsewhere" in said, said
    assert "IMG_9999 to IMG_0001" in said, said


class GroupTether(Tether):
    """A tethering program that saves ``files[n - 1]`` (a list of names and bytes, in order,
    each renamed over its final name) for the board's n-th shutter pulse."""

    def __init__(self, firmware, folder: Path, groups: list[list[tuple[str, bytes]]]) -> None:  # type: ignore[no-untyped-def]
        super().__init__(firmware, folder, [])
        self.groups = groups

    def run(self) -> None:
        saved = 0
        while not self.stop.is_set() and saved < len(self.groups):
            pulses = sum(e.what == "shutter" for e in list(self.firmware.history))
            if pulses > saved:
                for name, data in self.groups[saved]:
                    temporary = self.folder / f".{name}.tmp"
                    temporary.write_bytes(data)
                    os.replace(temporary, self.folder / name)
                saved += 1
            self.stop.wait(0.02)


def test_an_earlier_shoots_file_is_said_after_a_name_of_this_run_came_again(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A name of this run saved again (set aside, its light taken from the next file) and then
    an earlier shoot's file saved over: the stop had kept only the words on the first ("an
    earlier shot had it"), its own cause, the earlier shoot's file, unsaid."""
    tether = tmp_path / "tether"
    tether.mkdir()
    (tether / "IMG_0001.DNG").write_bytes(flat_dng(0.1) + b"earlier shoot")
    cfg = folder_watch_config(tmp_path, tether, timeout_s=10.0)
    groups = [
        [("IMG_0010.DNG", flat_dng(0.3))],
        [("IMG_0010.DNG", flat_dng(0.3) + b"again"), ("IMG_0011.DNG", flat_dng(0.3))],
        [("IMG_0001.DNG", flat_dng(0.3))],
    ]
    run = tethered_run(
        monkeypatch,
        cfg,
        tether,
        [],
        tmp_path / "s",
        camera=lambda fw: GroupTether(fw, tether, groups),
        lights=3,
    )
    said = run.said
    assert run.result.exit_code == 2, said
    assert "Traceback" not in said and not run.lit_at_end, said
    assert "IMG_0010.DNG appeared again as another file" in said, said
    assert "IMG_0001.DNG was in the folder before this run began" in said, said
    assert f"move the files already in {tether} elsewhere" in said, said
