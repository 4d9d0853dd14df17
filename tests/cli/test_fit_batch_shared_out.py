"""Two batches given one ``--out`` at once each finish their sessions, and a folder removed
under a fit is not called a full disk.

Each batch removed the other's in-progress partial folder as a killed run's leftover; both
then reported a session "failed … No such file or directory (ENOENT) … free space on that
disk … run again: rti-rig fit P/A --out FQ/.A.8195-….partial" (exit 2), though the session's
fit ended complete, and the advice named a hidden folder no user should give.
"""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import pytest
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.testing.kill_hooks import popen_argv

runner = CliRunner()


def sessions(tmp_path: Path) -> tuple[Path, Path]:
    """Sessions P/A and P/B, 6 lights each."""
    cfg = write_config(tmp_path, SMALL_DOME)
    a, b = tmp_path / "P" / "A", tmp_path / "P" / "B"
    for session in (a, b):
        r = runner.invoke(app, ["run", str(cfg), "--out", str(session), "--lights", "6"])
        assert r.exit_code == 0, r.output
    return a, b


def held_batch(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, a: Path, b: Path, fq: Path):  # type: ignore[no-untyped-def]
    """``rti-rig fit A B --out FQ`` in a child process, held as it is about to write A's
    fit.json into its partial folder: (the process, the hold file, its partial folder)."""
    hold = tmp_path / "hold"
    hold.touch()
    monkeypatch.setenv("RTI_RIG_HOLD", str(hold))
    args = ["fit", str(a), str(b), "--out", str(fq), "--model", "ps", "--no-qa"]
    proc = popen_argv("fit_hold", 0, args)
    reached = Path(f"{hold}.reached")
    deadline = time.monotonic() + 600
    while not reached.exists():  # a condition, with a generous bound: the machine is loaded
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the batch never reached A's fit.json"
        time.sleep(0.05)
    # its partial folder (beside it, the attempt's .owner record)
    (partial,) = [
        p for p in fq.iterdir() if p.name.startswith(f".A.{proc.pid}-") and p.suffix == ".partial"
    ]
    return proc, hold, partial


def release(proc, hold: Path) -> tuple[int, str]:  # type: ignore[no-untyped-def]
    """Let the held batch go on; its exit code and its output with line wrapping undone."""
    hold.unlink()
    out, err = proc.communicate(timeout=600)
    return proc.returncode, " ".join((out + err).decode().split())


@pytest.mark.e2e
@pytest.mark.slow
def test_two_batches_into_one_out_each_finish(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    a, b = sessions(tmp_path)
    fq = tmp_path / "FQ"
    proc, hold, partial = held_batch(tmp_path, monkeypatch, a, b, fq)
    try:
        r = runner.invoke(
            app, ["fit", str(a), str(b), "--out", str(fq), "--model", "ps", "--no-qa"]
        )
        assert r.exit_code == 0 and said(r).count(": done") == 2, r.output
        assert partial.is_dir()  # the running batch's folder is left to it
    finally:
        code, text = release(proc, hold)
    assert code == 0, text
    assert "failed" not in text and "free space" not in text, text
    assert sorted(p.name for p in fq.iterdir()) == ["A", "B"]
    r = runner.invoke(app, ["fit", str(a), str(b), "--out", str(fq), "--model", "ps", "--no-qa"])
    assert said(r).count("skipped (finished earlier)") == 2, r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_a_partial_folder_removed_under_a_fit_is_not_called_a_full_disk(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    a, b = sessions(tmp_path)
    fq = tmp_path / "FQ"
    proc, hold, partial = held_batch(tmp_path, monkeypatch, a, b, fq)
    try:
        shutil.rmtree(partial)  # removed by hand, or by an older rti-rig's batch
    finally:
        code, text = release(proc, hold)
    assert code == 2, text
    assert f"{a}: failed" in text and "No such file or directory" in text, text
    assert "free space" not in text and ".partial --out" not in text, text
    assert "its folder was removed while the fit wrote into it" in text, text
    assert f"then run the batch again with --out {fq}" in text, text
    assert f"{b}: done" in text, text


@pytest.mark.e2e
@pytest.mark.slow
def test_a_session_another_run_finished_meanwhile_is_done_not_failed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    a, b = sessions(tmp_path)
    fq = tmp_path / "FQ"
    proc, hold, partial = held_batch(tmp_path, monkeypatch, a, b, fq)
    try:
        shutil.rmtree(partial)  # as an older rti-rig's batch into the same --out did
        r = runner.invoke(
            app, ["fit", str(a), str(b), "--out", str(fq), "--model", "ps", "--no-qa"]
        )
        assert said(r).count(": done") == 2, r.output
    finally:
        code, text = release(proc, hold)
    assert code == 0, text
    assert f"{a}: done (by another run into the same --out, meanwhile)" in text, text
