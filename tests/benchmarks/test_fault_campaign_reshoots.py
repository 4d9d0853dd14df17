"""The fault campaign sees images set aside and shot again.

"Images lost" compares a session's final files with those committed before its faults; on the
simulated rigs a step shot again has the same bytes, so an image set aside and shot again had
gone unseen. :func:`benchmarks.fault_campaign.reshoots` counts them.
"""

from __future__ import annotations

from pathlib import Path

from conftest import SMALL_DOME, write_config
from typer.testing import CliRunner

from benchmarks.fault_campaign import note_committed, reshoots
from rti_rig.cli import app

runner = CliRunner()


def test_an_image_set_aside_and_shot_again_is_counted(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output
    seen: dict[int, set[str]] = {}
    note_committed(out, seen)
    assert reshoots(out, seen) == (0, 0)
    jpeg = out / "image_004.jpg"
    jpeg.write_bytes(jpeg.read_bytes()[:-10] + b"\0" * 10)
    r = runner.invoke(app, ["run", "--resume", str(out), "--reshoot-lost", "--no-verdict"])
    assert r.exit_code == 0, r.output
    # its JPEG (changed) and TIFF (as committed) set aside, and the step captured again: the
    # final files match the committed ones, so "images lost" alone saw nothing
    assert reshoots(out, seen) == (1, 1)
    note_committed(out, seen)  # noted again at the end: still one step shot again
    assert reshoots(out, seen) == (1, 1)
