"""The note of an export written outside its session, for relight-cli (which lists a
folder's ``.lp`` files by name and reads the first)."""

from __future__ import annotations

from pathlib import Path


def test_an_export_not_named_lp_is_told_relight_reads_only_lp(tmp_path: Path) -> None:
    """``export-lp S --out e.txt``: the note had said relight-cli "then reads e.txt there",
    after the note that no tool finds it by that name."""
    from rti_rig.app.usecases.export import relight_move_advice

    (tmp_path / "lights.lp").write_text("1\nimage_001.jpg 0 0 1\n")
    said = relight_move_advice(tmp_path, "e.txt")
    assert said == "relight-cli reads only a file named .lp: name it e.lp there", said
    assert "then reads e.lp there" in relight_move_advice(tmp_path, "e.lp")


def test_an_export_not_named_lp_inside_the_session_is_not_what_relight_reads(
    tmp_path: Path,
) -> None:
    """Written inside the session as e.txt: the note had said relight-cli "reads the first .lp
    there by name, now e.txt" (a review found the inside-session note left as it was)."""
    from rti_rig.app.usecases.export import _relight_reads

    (tmp_path / "lights.lp").write_text("1\nimage_001.jpg 0 0 1\n")
    assert _relight_reads(tmp_path, "e.txt").endswith("still lights.lp")
    assert "now a.lp" in _relight_reads(tmp_path, "a.lp")
    (tmp_path / "lights.lp").unlink()
    assert _relight_reads(tmp_path, "e.txt").endswith("finds no .lp there")
