"""ensure_writable_folder: created and proven writable, or refused by name (no traceback)."""

from __future__ import annotations

import errno
import os
from pathlib import Path

import pytest

from rti_rig.core.errors import RtiRigError
from rti_rig.core.out_folders import (
    ensure_writable_folder,
    fit_beside,
    free_folder_beside,
    free_name,
)


def test_a_new_folder_is_created_and_left_empty(tmp_path: Path) -> None:
    target = tmp_path / "a" / "b"
    ensure_writable_folder(target)
    assert target.is_dir() and not any(target.iterdir())  # the probe file is gone


def test_a_folder_under_a_file_is_refused_by_name(tmp_path: Path) -> None:
    a_file = tmp_path / "f"
    a_file.write_text("x")
    with pytest.raises(RtiRigError, match=r"--out .*f/sub: .*f is a file, not a folder: give a"):
        ensure_writable_folder(a_file / "sub")
    assert a_file.read_text() == "x"


def test_a_folder_nothing_can_be_created_in_is_refused() -> None:
    # /proc stands in for a read-only card (the tests may run as root, whom modes do not stop)
    with pytest.raises(RtiRigError, match="cannot write there"):
        ensure_writable_folder(Path("/proc/rti-rig-cannot-write-here"))


def test_an_existing_folder_refusing_a_new_file_is_not_said_to_be_missing() -> None:
    """The probe's reason named the folder as its file: "(No such file or directory: /proc)"
    read as if /proc did not exist. ``ensure_file_writable`` words it the same way (its CLI
    test: tests/app/test_plan_figure.py)."""
    with pytest.raises(RtiRigError) as caught:
        ensure_writable_folder(Path("/proc"))
    assert str(caught.value) == (
        "--out /proc: cannot write there (the system refused a new file in /proc: No such file "
        "or directory); choose a folder you can write to"
    )


def test_a_folder_the_user_may_not_look_into_is_refused_by_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--out /root/x/y`` of a user who may not look into /root: ``Path.exists`` raises
    PermissionError on Python 3.11 (it does not say False); it had escaped as a traceback.
    The tests may run as root, whom modes do not stop: ``os.stat`` refuses as for them."""
    locked = tmp_path / "locked"
    locked.mkdir()
    real_stat = os.stat

    def stat(path: object, *args: object, **kwargs: object) -> os.stat_result:
        if str(path).startswith(f"{locked}{os.sep}"):
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))
        return real_stat(path, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(os, "stat", stat)
    target = locked / "x" / "y"
    with pytest.raises(RtiRigError, match=r"--out .*/x/y: cannot write there \(Permission denied"):
        ensure_writable_folder(target)
    monkeypatch.undo()
    assert not (locked / "x").exists()


def test_a_free_name_skips_what_is_taken_a_broken_link_too(tmp_path: Path) -> None:
    """The name a hint gives for the file or folder its command writes: taken names (a broken
    symlink included: ``plan`` and ``run`` would refuse it) get ``-2``, ``-3``… before a file's
    suffix, at the end of a folder's name (its dots are its own: ``v1.2`` is no suffix)."""
    assert free_name(tmp_path / "plan.lp") == tmp_path / "plan.lp"
    (tmp_path / "plan.lp").write_text("3\n")
    (tmp_path / "plan-2.lp").symlink_to(tmp_path / "gone")
    assert free_name(tmp_path / "plan.lp") == tmp_path / "plan-3.lp"
    session = tmp_path / "scan v1.2"
    session.mkdir()
    assert free_folder_beside(session, "fit") == tmp_path / "scan v1.2-fit"
    (tmp_path / "scan v1.2-fit").mkdir()
    assert free_folder_beside(session, "fit") == tmp_path / "scan v1.2-fit-2"


def test_a_folder_beside_a_session_given_as_dot_or_dotdot_is_named_from_its_real_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A session given as ``.`` (``rti-rig fit .`` from inside it) or ``..`` has no name to
    add ``-fit`` to: ``Path('.').with_name`` raised ValueError (a traceback in a hint), and
    ``..-fit`` named a folder nobody meant. The folder is named from the absolute path."""
    session = tmp_path / "scan 3"
    (session / "images").mkdir(parents=True)
    monkeypatch.chdir(session)
    assert free_folder_beside(Path("."), "fit") == tmp_path / "scan 3-fit"
    monkeypatch.chdir(session / "images")
    assert free_folder_beside(Path(".."), "fit") == tmp_path / "scan 3-fit"
    (tmp_path / "scan 3-fit").mkdir()
    assert free_folder_beside(Path(".."), "again") == tmp_path / "scan 3-again"
    assert free_folder_beside(Path("../."), "fit") == tmp_path / "scan 3-fit-2"


def test_the_fit_beside_a_session_pastes_back_to_it_and_a_free_folder(tmp_path: Path) -> None:
    """The one fit command every complete session's hint names: both paths one shell word
    each, its --out beside the session and not taken."""
    import shlex

    session = tmp_path / "Object 12"
    (tmp_path / "Object 12-fit").mkdir()
    words = shlex.split(fit_beside(session))
    assert words == ["rti-rig", "fit", str(session), "--out", str(tmp_path / "Object 12-fit-2")]
