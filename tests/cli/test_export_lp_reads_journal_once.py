"""``export-lp`` reads a session's journal once (and once more under the lock where it
completes the lights.lp of a run stopped between a record file and its journal line).

Before, each of its readers scanned ``journal.jsonl`` again: the listing, the unchecked images,
the files lost since capture, the renamed ones, the advice (four to six scans of one session),
each scan checking every record file the journal lacks against its images. What it says is
unchanged (the other export-lp tests hold it).
"""

from __future__ import annotations

import signal
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.testing.kill_hooks import popen_session

runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


@pytest.mark.slow
@pytest.mark.e2e
def test_export_lp_reads_the_journal_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "s"
    # killed between image_005's record file and its journal line, then image_002 deleted:
    # the listing, the image left out, its advice and the lost files all come from the journal
    proc = popen_session("after_record", 4, CONFIGS / "simulated_dome.toml", out, 8)
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    (out / "image_002.jpg").unlink()

    reads: list[str] = []
    real = Path.read_bytes

    def read_bytes(self: Path) -> bytes:
        if self.name == "journal.jsonl":
            reads.append(str(self))
        return real(self)

    monkeypatch.setattr(Path, "read_bytes", read_bytes)
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "4 lights" in text and "left out, missing or changed" in text, text
    assert "image_002.jpg" in text, text
    # one scan for everything export-lp says, and one more, under the session's lock, by the
    # completion of lights.lp this stopped run needs (it must not act on a scan a --resume may
    # have overtaken: list_unwritten_step); before, four to six
    assert reads == [str(out / "journal.jsonl")] * 2, reads
    assert "lights.lp now lists image_005 too" in text, text
