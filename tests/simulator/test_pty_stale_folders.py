"""The emulated ports' folders (``rti-rig-pty-*`` in the temporary directory) that an emulator
killed outright left behind are removed when the next one starts; a live one's never.

An emulator removes its folder as it ends, but SIGKILL (a test's timeout, an out-of-memory
kill) gives it no chance: the folders had piled up in /tmp, one per kill.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
from conftest import line_within

from rti_rig.simulator.pty_link import (
    PTY_FOLDER_PREFIX,
    PTY_OWNER_FILE,
    _start_time,
    owner_line,
    remove_stale_pty_folders,
)


def _folder(root: Path, name: str, owner: str | None) -> Path:
    folder = root / f"{PTY_FOLDER_PREFIX}{name}"
    folder.mkdir()
    (folder / "tty-dome").symlink_to("/dev/null")  # as a port's link: removed, not followed
    if owner is not None:
        (folder / PTY_OWNER_FILE).write_text(owner)
    return folder


def _dead_pid() -> int:
    """The pid of a process that has ended (started and waited for by this test)."""
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait(timeout=60)
    return proc.pid


def test_only_folders_whose_owner_is_gone_are_removed(tmp_path: Path) -> None:
    me = os.getpid()
    dead = _folder(tmp_path, "dead", f"{_dead_pid()} 1\n")
    reused = _folder(tmp_path, "reused", f"{me} 1\n")  # this pid, but a process started before
    live = _folder(tmp_path, "live", f"{me} {_start_time(me)}\n")
    unknown = _folder(tmp_path, "unknown", None)  # no owner file: who serves it is not known
    garbled = _folder(tmp_path, "garbled", "not a pid\n")
    removed = remove_stale_pty_folders(tmp_path)
    assert sorted(removed) == sorted([dead, reused])
    assert not dead.exists() and not reused.exists()
    assert live.is_dir() and unknown.is_dir() and garbled.is_dir()
    assert Path("/dev/null").exists()


def test_a_folder_of_another_pid_namespace_is_left_alone(tmp_path: Path) -> None:
    """A container sharing this temporary directory serves its emulator under a pid that
    means nothing here: its folder is kept, as any whose owner cannot be told."""
    here = owner_line().split()
    assert len(here) == 3 and here[0] == str(os.getpid()), here  # as serve_on_pty writes it
    dead = _dead_pid()
    other = _folder(tmp_path, "other", f"{dead} 1 pid:[1]\n")
    ours = _folder(tmp_path, "ours", f"{dead} 1 {here[2]}\n")
    assert remove_stale_pty_folders(tmp_path) == [ours]
    assert other.is_dir() and not ours.exists()


@pytest.mark.slow  # two emulator processes
@pytest.mark.pty
@pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux")
def test_a_killed_emulators_folder_is_removed_when_the_next_one_starts(tmp_path: Path) -> None:
    """Through the emulator's own command line, in a temporary directory of the test's own."""
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    argv = [sys.executable, "-m", "rti_rig.simulator.dome_firmware", "--profile", "nab-rti-v1"]

    def serve() -> tuple[subprocess.Popen[str], Path]:
        proc = subprocess.Popen(argv, stdout=subprocess.PIPE, text=True, env=env)
        line = line_within(proc, 120, "the served firmware's port")
        port = Path(line.split()[-1])
        assert port.parent.parent == tmp_path, line
        return proc, port.parent

    first, first_folder = serve()
    first.kill()  # SIGKILL: no clean-up of its own
    first.wait(timeout=60)
    assert first_folder.is_dir()  # left behind, as before
    second, second_folder = serve()
    try:
        assert not first_folder.exists()
        assert second_folder.is_dir() and second_folder != first_folder
        third, third_folder = serve()  # a live one's folder is left alone
        try:
            assert second_folder.is_dir() and third_folder.is_dir()
        finally:
            third.send_signal(signal.SIGINT)
            third.wait(timeout=60)
    finally:
        second.send_signal(signal.SIGINT)  # the process this test started, by its own handle
        second.wait(timeout=60)
    assert not second_folder.exists() and not third_folder.exists()  # ended as Ctrl-C ends it
    assert tempfile.gettempdir() != str(tmp_path)  # the test's TMPDIR was the children's only
