"""A batch leaves another host's attempt folder in a shared ``--out`` to it, and says so once.

A killed run's partial folder was removed when the PID in its name did not run *on this host*;
on a shared ``--out`` (a lab NAS, where Dask workers on several hosts fit into one folder) a
running fit on another host has a PID that means nothing here, and its folder was removed
under it. An attempt now records its host (name, machine id, boot id), PID namespace, PID and
start time beside its folders (``.OUTPUT.ATTEMPT.owner``); a folder is removed only when that
host is this one and the process is gone. An older rti-rig's folder, which records no host, is
taken as this host's, and its removal is said.
"""

from __future__ import annotations

import json
import re
import shlex
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import dead_pid
from typer.testing import CliRunner

from rti_rig.app.usecases.fit_attempts import AttemptFolder, Kind
from rti_rig.app.usecases.fit_owners import owner_of, owner_record_path, this_process
from rti_rig.cli import app

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

runner = CliRunner(env={"COLUMNS": "400"})
FIT = ["--no-qa", "--model", "ps"]


def two_sessions(tmp_path: Path) -> tuple[Path, Path]:
    a, b = tmp_path / "P" / "A", tmp_path / "P" / "B"
    for s in (a, b):
        make_session(s, size=(24, 32))
    return a, b


def left_attempt(out: Path, pid: int, record: dict[str, Any] | None) -> Path:
    """Session A's partial folder of an attempt by ``pid``, half written, with ``record`` as
    its owner record (None: an older rti-rig's, which wrote none)."""
    attempt = AttemptFolder("A", f"{pid}-0badc0de", Kind.PARTIAL)
    folder = attempt.path(out)
    folder.mkdir(parents=True)
    (folder / "normals.npy").write_bytes(b"half")
    if record is not None:
        owner_record_path(attempt, out).write_text(json.dumps(record), encoding="utf-8")
    return folder


def batch(a: Path, b: Path, out: Path) -> tuple[int, str]:
    r = runner.invoke(app, ["fit", str(a), str(b), "--out", str(out), *FIT])
    return r.exit_code, " ".join(r.output.split())


def test_another_host_s_attempt_is_left_to_it_and_said_once(tmp_path: Path) -> None:
    a, b = two_sessions(tmp_path)
    out = tmp_path / "F Q's"  # its rm -r pastes back: it had been hand-quoted '...'
    pid = dead_pid()  # not running here: it had been removed as a killed run's
    record = {**this_process(), "host": "lab-node-7", "pid": pid, "started": "123"}
    folder = left_attempt(out, pid, record)
    code, said = batch(a, b, out)
    assert code == 0, said
    assert folder.is_dir() and (folder / "normals.npy").read_bytes() == b"half"
    assert (out / "A" / "fit.json").is_file()  # this batch fits its own copy all the same
    note = f"{folder} is the folder of a fit running on host lab-node-7 (PID {pid} there)"
    assert said.count(note) == 1, said
    assert "if that host is gone" in said, said
    word = re.search(r"\(rm -r (.+?)\) and run the same command again", said)
    assert word is not None and shlex.split(word[1]) == [str(folder)], said
    # the finished session's end-of-fit clean-up leaves it too; the next run says it again
    code, said = batch(a, b, out)
    assert code == 0 and folder.is_dir() and said.count(note) == 1, said


def test_this_host_s_attempt_whose_process_is_gone_is_removed_with_its_record(
    tmp_path: Path,
) -> None:
    a, b = two_sessions(tmp_path)
    out = tmp_path / "FQ"
    pid = dead_pid()
    folder = left_attempt(out, pid, {**this_process(), "pid": pid, "started": "1"})
    code, said = batch(a, b, out)
    assert code == 0, said
    assert not folder.exists(), said
    assert "running on" not in said and "older rti-rig" not in said, said
    # nothing hidden is left: no attempt's folder nor owner record
    assert sorted(p.name for p in out.iterdir()) == ["A", "B"]


@pytest.mark.parametrize("change", ["started", "boot_id"])
def test_a_live_pid_of_another_process_or_of_before_a_restart_is_gone(
    tmp_path: Path, change: str
) -> None:
    """The PID runs here, but it is not the recorded process: its start time differs (the PID
    was reused), or this host has restarted since (another boot id)."""
    a, b = two_sessions(tmp_path)
    out = tmp_path / "FQ"
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    try:
        record = {**this_process(), "pid": live.pid}
        record["started"] = this_process_started(live.pid)
        folder = left_attempt(out, live.pid, record)
        assert not owner_of(folder, mine_too=True).gone  # the very process: left to it
        record[change] = "0" if change == "started" else "another-boot"
        owner_record_path(AttemptFolder.parse(folder.name), out).write_text(  # type: ignore[arg-type]
            json.dumps(record), encoding="utf-8"
        )
        code, said = batch(a, b, out)
    finally:
        live.kill()
        live.wait(timeout=120)
    assert code == 0, said
    assert not folder.exists(), said


def this_process_started(pid: int) -> str:
    """Process ``pid``'s start time as an owner record holds it."""
    from rti_rig.app.usecases.fit_owners import _start_time

    started = _start_time(pid)
    assert started is not None
    return started


def test_an_older_rti_rig_s_folder_is_taken_as_this_host_s_and_its_removal_said(
    tmp_path: Path,
) -> None:
    a, b = two_sessions(tmp_path)
    out = tmp_path / "FQ"
    pid = dead_pid()
    folder = left_attempt(out, pid, None)
    code, said = batch(a, b, out)
    assert code == 0, said
    assert not folder.exists()
    assert f"removed {folder}, left by an interrupted fit of an older rti-rig" in said, said
    assert f"its PID {pid} was taken as this host's" in said, said


def test_another_pid_namespace_or_an_unreadable_record_is_not_judged_here(
    tmp_path: Path,
) -> None:
    """A container sharing this host's name has PIDs of its own; a record that cannot be read
    names no host: both are left, said as elsewhere."""
    pid = dead_pid()
    folder = left_attempt(tmp_path, pid, {**this_process(), "pid": pid, "pid_namespace": "x"})
    owner = owner_of(folder, mine_too=True)
    assert not owner.gone and "another PID namespace" in owner.elsewhere
    owner_record_path(AttemptFolder.parse(folder.name), tmp_path).write_text("{")  # type: ignore[arg-type]
    owner = owner_of(folder, mine_too=True)
    assert not owner.gone and "unreadable" in owner.elsewhere


def test_a_cluster_batch_leaves_another_host_s_attempt_and_says_so(tmp_path: Path) -> None:
    """The same through ``--scheduler`` on a local cluster: the worker's own end-of-fit
    clean-up leaves the folder too."""
    from distributed import LocalCluster

    a, b = two_sessions(tmp_path)
    out = tmp_path / "FQ"
    pid = dead_pid()
    folder = left_attempt(out, pid, {**this_process(), "host": "lab-node-7", "pid": pid})
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        args = ["fit", str(a), str(b), "--out", str(out), *FIT]
        r = runner.invoke(app, [*args, "--scheduler", cluster.scheduler_address])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert folder.is_dir() and (out / "A" / "fit.json").is_file(), said
    assert said.count(f"{folder} is the folder of a fit running on host lab-node-7") == 1, said


def _without_machine_id(monkeypatch: pytest.MonkeyPatch) -> None:
    """This host lacks /etc/machine-id (as some containers and minimal installs do)."""
    from rti_rig.app.usecases import fit_owners

    real = fit_owners._read
    monkeypatch.setattr(
        fit_owners, "_read", lambda path: None if path == "/etc/machine-id" else real(path)
    )


def test_a_host_of_the_same_name_without_machine_ids_is_left_and_said(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two hosts sharing a host name, neither with a machine id: the other's boot id differs
    from this one's, which had been read as this host restarted since (its running fit's
    folder removed). Which host it is cannot be told: the folder is left, and said once."""
    _without_machine_id(monkeypatch)
    a, b = two_sessions(tmp_path)
    out = tmp_path / "FQ"
    pid = dead_pid()  # means nothing here: the PID of the other host's running fit
    record = {**this_process(), "boot_id": "the-other-host-s-boot", "pid": pid, "started": "9"}
    assert record["machine_id"] is None and record["host"] == this_process()["host"]
    folder = left_attempt(out, pid, record)
    code, said = batch(a, b, out)
    assert code == 0, said
    assert folder.is_dir() and (folder / "normals.npy").read_bytes() == b"half", said
    assert (out / "A" / "fit.json").is_file()
    note = f"{folder} is the folder of a fit running on host {record['host']}, or on this host"
    assert said.count(note) == 1, said
    assert "which of the two cannot be told" in said, said
    assert f"rm -r {shlex.quote(str(folder))})" in said, said


def test_without_machine_ids_the_same_boot_tells_this_host(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same boot id is one running kernel, this host's: a killed fit's folder there is
    still removed without a machine id; and a machine id of the record's alone (this host
    has none) establishes nothing."""
    _without_machine_id(monkeypatch)
    pid = dead_pid()
    folder = left_attempt(tmp_path, pid, {**this_process(), "pid": pid, "started": "1"})
    assert owner_of(folder, mine_too=True).gone
    record = {**this_process(), "machine_id": "abc", "boot_id": "x", "pid": pid}
    owner_record_path(AttemptFolder.parse(folder.name), tmp_path).write_text(  # type: ignore[arg-type]
        json.dumps(record), encoding="utf-8"
    )
    owner = owner_of(folder, mine_too=True)
    assert not owner.gone and "cannot be told" in owner.elsewhere, owner


def set_aside(out: Path, fit: Path, pid: int, attempt: str, record: dict[str, Any]) -> Path:
    """A copy of finished fit ``fit`` as session A's earlier fit set aside by a refit's
    attempt ``PID-attempt`` (``.A.PID-attempt.earlier``), with ``record`` as its owner."""
    import shutil

    folder = AttemptFolder("A", f"{pid}-{attempt}", Kind.EARLIER)
    shutil.copytree(fit, folder.path(out))
    owner_record_path(folder, out).write_text(json.dumps(record), encoding="utf-8")
    return folder.path(out)


@pytest.mark.parametrize("scheduler", [False, True], ids=["here", "on a local cluster"])
def test_an_interrupted_swap_is_finished_leaving_another_host_s_set_aside_fit(
    tmp_path: Path, scheduler: bool
) -> None:
    """A refit of this host killed between its two renames is finished by the next run (its
    complete new fit put in place); another host's refit, which set its own earlier fit aside
    in the same ``--out`` (older, by time), is running as far as this host can tell: its folder
    had been removed unjudged with this host's older set-aside fits. It is left, and said
    once with what to do if that host is gone."""
    import os
    import shutil

    a, b = two_sessions(tmp_path)
    out = tmp_path / "FQ"
    code, said = batch(a, b, out)
    assert code == 0, said
    fitted = tmp_path / "fitted-A"
    shutil.move(out / "A", fitted)  # session A's fit, to stand for the set-aside fits
    pid, theirs = dead_pid(), dead_pid()
    other = {**this_process(), "host": "lab-node-7", "pid": theirs, "started": "5"}
    elsewhere = set_aside(out, fitted, theirs, "0badf00d", other)
    os.utime(elsewhere, (1_000_000_000, 1_000_000_000))  # set aside first: the older
    mine = set_aside(out, fitted, pid, "0badc0de", {**this_process(), "pid": pid, "started": "1"})
    new = AttemptFolder("A", f"{pid}-0badc0de", Kind.PARTIAL).path(out)
    shutil.copytree(fitted, new)  # the new fit, complete: the kill came between the renames
    args = ["fit", str(a), str(b), "--out", str(out), *FIT]
    if scheduler:
        from distributed import LocalCluster

        with LocalCluster(
            n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster:
            r = runner.invoke(app, [*args, "--scheduler", cluster.scheduler_address])
    else:
        r = runner.invoke(app, args)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "the new fit, complete, was put in place in" in said, said
    assert (out / "A" / "fit.json").is_file() and not mine.exists() and not new.exists()
    assert (elsewhere / "fit.json").read_bytes() == (fitted / "fit.json").read_bytes(), said
    note = f"{elsewhere} is the folder of a fit running on host lab-node-7 (PID {theirs} there)"
    assert said.count(note) == 1, said
    assert f"rm -r {shlex.quote(str(elsewhere))})" in said and "if that host is gone" in said, said
    # this host's attempt leaves nothing behind; the other host's record stays with its folder
    assert not owner_record_path(AttemptFolder.parse(mine.name), out).exists()  # type: ignore[arg-type]
    assert owner_record_path(AttemptFolder.parse(elsewhere.name), out).exists()  # type: ignore[arg-type]
