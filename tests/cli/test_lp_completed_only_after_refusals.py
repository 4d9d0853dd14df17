"""``fit`` completes a session's ``lights.lp`` (left one image short by a run stopped between a
step's record file and its journal line) only once every refusal has passed, never of a
disowned session, and says so; the note claims nothing about images the session may have lost.

Before, ``fit`` rewrote ``lights.lp`` before its own refusals — of a disowned session, and of
one refused for a non-empty ``--out`` — without a word; and the note said ``lights.lp`` "lists
the 4 images the session holds" of a session that had lost one of them.
"""

from __future__ import annotations

import shutil
import signal
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp
from rti_rig.runtime.disowned import MARKER
from rti_rig.testing.kill_hooks import popen_session

runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


@pytest.fixture(scope="module")
def stopped(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A shipped-config dry run SIGKILLed right after image_004's record file was written."""
    out = tmp_path_factory.mktemp("stopped") / "s"
    proc = popen_session("after_record", 3, CONFIGS / "simulated_dome.toml", out, 8)
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    assert [e.name for e in read_lp(out / "lights.lp")] == [f"image_00{i}.jpg" for i in (1, 2, 3)]
    return out


def _copy(stopped: Path, to: Path) -> Path:
    shutil.copytree(stopped, to)
    return to


@pytest.mark.slow
@pytest.mark.e2e
def test_a_disowned_session_refused_by_fit_keeps_its_lights_lp(
    stopped: Path, tmp_path: Path
) -> None:
    s = _copy(stopped, tmp_path / "dis")
    (s / MARKER).write_text("slip check: labels not verified\n", encoding="utf-8")
    before = (s / "lights.lp").read_bytes()
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "f"), "--model", "ps"])
    assert r.exit_code != 0, r.output
    assert MARKER in said(r), said(r)
    assert (s / "lights.lp").read_bytes() == before


@pytest.mark.slow
@pytest.mark.e2e
def test_a_fit_refused_for_a_non_empty_out_keeps_lights_lp(stopped: Path, tmp_path: Path) -> None:
    s = _copy(stopped, tmp_path / "q")
    before = (s / "lights.lp").read_bytes()
    full = tmp_path / "full"
    full.mkdir()
    (full / "keep.txt").write_text("mine\n", encoding="utf-8")
    r = runner.invoke(app, ["fit", str(s), "--out", str(full), "--model", "ps"])
    assert r.exit_code != 0, r.output
    assert "not empty" in said(r), said(r)
    assert (s / "lights.lp").read_bytes() == before
    # a model the lights cannot support is refused alike, with lights.lp untouched
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "h"), "--model", "hsh3"])
    assert r.exit_code != 0, r.output
    assert (s / "lights.lp").read_bytes() == before
    # the fit that passes its refusals completes it, and says so
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "ok"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    assert "lights.lp now lists image_004 too" in said(r), said(r)
    assert [e.name for e in read_lp(s / "lights.lp")] == [f"image_00{i}.jpg" for i in range(1, 5)]


@pytest.mark.slow
@pytest.mark.e2e
def test_the_note_claims_nothing_of_an_image_the_session_lost(
    stopped: Path, tmp_path: Path
) -> None:
    s = _copy(stopped, tmp_path / "m")
    (s / "image_002.jpg").unlink()
    (s / "linear" / "image_002.tif").unlink()
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(tmp_path / "m_x.lp")])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "3 lights" in text, text
    assert "lights.lp now lists image_004 too" in text, text
    assert "images the session holds" not in text, text
