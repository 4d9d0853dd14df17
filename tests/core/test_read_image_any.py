"""Reading a listed image that is not there is one clear error, not an OpenCV warning line
followed by a vaguer one (`bench tradeoff --from` on an acquisition missing a JPEG)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rti_rig.core.errors import SessionError
from rti_rig.core.image_files import read_image_any


def test_a_missing_image_is_named_without_an_opencv_warning(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    missing = tmp_path / "image05.jpg"
    with pytest.raises(SessionError, match=r"image05\.jpg: there is no such file"):
        read_image_any(missing)
    captured = capfd.readouterr()
    assert "WARN" not in captured.err + captured.out
