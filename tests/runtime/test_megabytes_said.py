"""A disk-space refusal's two figures read differently when they differ.

"need about 10 MB, 10 MB free; free at least 1 MB" had refused a replayed session for the
0.4 MB the rounding hid (QA, 2026-12-06): the figures take as many decimals as they need.
"""

from __future__ import annotations

from rti_rig.runtime.session import megabytes_said


def test_close_figures_take_the_decimals_that_tell_them_apart() -> None:
    assert megabytes_said(10_400_000, 10_000_000) == ("10.4 MB", "10.0 MB")
    assert megabytes_said(10_004_000, 10_001_000) == ("10.004 MB", "10.001 MB")
    assert megabytes_said(25_000_000, 3_000_000) == ("25 MB", "3 MB")  # far apart: whole MB
    assert megabytes_said(5_000_000, 5_000_000) == ("5 MB", "5 MB")


def test_the_refusal_says_them_so(tmp_path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    import shutil
    from collections import namedtuple

    import pytest

    from rti_rig.runtime.session import NoSpaceError, check_free_space

    usage = namedtuple("usage", "total used free")
    # 8 MiB of margin + 2 images of 1 MB: 10.39 MB needed, 10.0 MB free
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage(10**9, 0, 10_000_000))
    with pytest.raises(NoSpaceError) as exc:
        check_free_space(tmp_path, 2, 1_000_000)
    assert "need about 10.4 MB, 10.0 MB free" in str(exc.value), exc.value
