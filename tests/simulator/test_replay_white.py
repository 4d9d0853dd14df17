"""The replay camera's white level: read from the acquisition as it connects, or, for a resumed
session, kept as the session's images so far are labelled (the acquisition not read again).

Why: a replay session begun at one white and resumed at another would label its images with two
white levels (its fit then refuses them, its verdict has no single scale), and a resume had read
the whole acquisition again before its first light.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import tifffile

from rti_rig.core.clock import VirtualClock
from rti_rig.core.image_files import write_linear_tiff
from rti_rig.simulator.replay import ReplayCamera


class _Dome:
    lit: int | None = 0


def _camera(tmp_path: Path, calls: list[int]) -> ReplayCamera:
    recorded = tmp_path / "acq" / "image01.tif"
    recorded.parent.mkdir()
    tifffile.imwrite(recorded, np.full((4, 6, 3), 900, np.uint16))

    def reading() -> tuple[int, str | None]:
        calls.append(1)
        return 4095, "replayed with white level 4095, not 65535: read"

    return ReplayCamera([recorded], _Dome(), VirtualClock(), shape=(4, 6), white_reading=reading)


def _session_with(root: Path, label: str) -> None:
    (root / "linear").mkdir(parents=True)
    write_linear_tiff(
        root / "linear" / "image_001.tif",
        np.zeros((4, 6, 3), np.uint16),
        description=label,
    )


def test_a_new_session_reads_the_white_as_the_camera_connects(tmp_path: Path) -> None:
    calls: list[int] = []
    camera = _camera(tmp_path, calls)
    camera.bind_session(tmp_path / "new")  # nothing in it yet
    assert calls == []  # not read until the camera connects (a dry build reads nothing)
    camera.connect()
    frame = camera.capture(0.1)
    assert calls == [1] and frame.white_level == 4095
    assert "replayed with white level 4095" in " ".join(frame.metadata["notices"])


@pytest.mark.parametrize(
    ("white", "said"),
    [(65535, None), (4095, "as this session's images so far are labelled")],
)
def test_a_resumed_session_keeps_the_white_its_images_are_labelled_with(
    tmp_path: Path, white: int, said: str | None
) -> None:
    calls: list[int] = []
    camera = _camera(tmp_path, calls)
    root = tmp_path / "s"
    _session_with(root, f"rti-rig: linear sRGB, 16-bit, white level {white} (the camera's own)")
    camera.bind_session(root)
    camera.connect()
    frame = camera.capture(0.1)
    assert calls == []  # the acquisition is not read again
    assert frame.white_level == white
    notices = " ".join(frame.metadata.get("notices") or [])
    if said is None:
        assert "white level" not in notices
    else:
        assert said in notices
