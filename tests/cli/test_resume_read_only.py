"""``run --resume`` of a session on read-only media says nothing is lost and what to do.

The resume rewrites ``lights.lp`` as it opens, so a session on a disk mounted read-only ended
with a bare ``error: cannot write …/lights.lp: Read-only file system (EROFS)``; the advice the
capture gives for that disk was never reached. The test runs as root (chmod blocks nothing), so
the disk's refusal is made in-process (:func:`rti_rig.testing.disk_faults.failing_writes`).
"""

from __future__ import annotations

import errno
from pathlib import Path

from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp
from rti_rig.testing.disk_faults import failing_writes

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


def test_a_resume_on_a_read_only_disk_says_nothing_is_lost_and_what_to_do(
    tmp_path: Path,
) -> None:
    out = tmp_path / "RO2"
    cfg = str(REPO / "rig_configs" / "simulated_dome.toml")
    with failing_writes("jpeg", after=3, errno_code=errno.ENOSPC):  # an interrupted session
        r = runner.invoke(app, ["run", cfg, "--out", str(out), "--lights", "12"])
    assert r.exit_code == 2, r.output
    kept = sorted(p.name for p in out.glob("image_*.jpg"))
    assert len(kept) == 3

    with failing_writes("lp", after=0, errno_code=errno.EROFS) as fault:
        r = runner.invoke(app, ["run", "--resume", str(out)])
    assert fault.failed == 1
    text = said(r)
    assert r.exit_code == 2, text
    assert "Traceback" not in text
    assert f"cannot write {out / 'lights.lp'}: Read-only file system (EROFS)" in text
    assert "nothing captured is lost" in text, text
    assert "make that disk writable again" in text, text
    assert "copy the session folder to a writable disk and resume the copy" in text, text
    assert f"rti-rig run --resume {out}" in text
    assert sorted(p.name for p in out.glob("image_*.jpg")) == kept

    r = runner.invoke(app, ["run", "--resume", str(out)])  # the disk writable again
    assert r.exit_code == 0, r.output
    assert len(read_lp(out / "lights.lp")) == 12
