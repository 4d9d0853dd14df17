"""A command whose stdout is a pipe its reader made non-blocking (``O_NONBLOCK``: node's
``child_process``, some CI runners) waits for room in the pipe, as with any other pipe, and
says every word.

A write to the full pipe raised ``BlockingIOError``: taken as output that could not be written,
the rest of the words were dropped (a ``--help`` read by such a parent stopped at 3 kB of its
13). Through ``python -m rti_rig`` on a real pipe, made small and filled before the command
starts, so that its first write finds no room. The pipe is read once the command has met it
full (ended, or waiting for room), never after a guessed time: read after 5 s, as it had been,
a loaded machine's command had not yet written, and one that drops its words passed.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import REPO, ended_on_exit, full_pipe, rti_rig_on_pipe, unread_in_pipe


def _waits_for_room(pid: int) -> bool:
    """Whether a thread of process ``pid`` is blocked in select/poll (the kernel's
    ``poll_schedule_timeout``, ``do_select``): where a non-blocking write that found no room
    waits for the reader. Nothing else in ``--help`` selects."""
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return False
    for task in tasks:
        try:
            with open(f"/proc/{pid}/task/{task}/wchan") as wchan:
                where = wchan.read()
        except OSError:
            continue
        if "poll" in where or "select" in where:
            return True
    return False


def _read_all(fd: int) -> bytes:
    with os.fdopen(fd, "rb") as stream:
        return stream.read()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="needs Linux's F_SETPIPE_SZ")
def test_help_on_a_full_non_blocking_pipe_is_said_whole(tmp_path: Path) -> None:
    env = {**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "80"}
    whole = subprocess.run(
        [sys.executable, "-m", "rti_rig", "run", "--help"],
        capture_output=True,
        env=env,
        timeout=600,
    ).stdout
    assert len(whole) > 4096, whole  # more than the pipe holds: the command must wait for room

    read_end, write_end, filler = full_pipe(writer_blocking=False)
    with open(tmp_path / "stderr.txt", "wb") as stderr:
        command = rti_rig_on_pipe(["-m", "rti_rig", "run", "--help"], write_end, stderr, 80)
    with ended_on_exit(command):
        # The pipe is read only once the command has met it full: it ended (a command that
        # drops its words) or one of its threads waits for room in it (select/poll). Read
        # sooner (the 5 s this had waited, on a loaded machine), the room made let a command
        # that drops its words pass.
        deadline = time.monotonic() + 600
        while command.poll() is None and not _waits_for_room(command.pid):
            assert time.monotonic() < deadline, "the command neither ended nor waited in 600 s"
            time.sleep(0.05)
        assert unread_in_pipe(read_end) == len(filler)  # nothing was read before it met the pipe
        said = _read_all(read_end)
        code = command.wait(timeout=600)
    errors = (tmp_path / "stderr.txt").read_text()
    assert code == 0, errors
    assert "could not be written" not in errors and "Traceback" not in errors, errors
    assert said == filler + whole, (len(said), len(filler) + len(whole))


def test_a_descriptor_with_no_room_is_written_once_the_reader_makes_room() -> None:
    """Below the text stream, the count is exact: what one write could not take goes out with
    the next, nothing twice, nothing lost (the wait itself is the pipe's: a thread reads)."""
    import threading

    from rti_rig.cli.app import waiting_when_nonblocking

    read_end, write_end = os.pipe()
    os.set_blocking(write_end, False)
    with open(write_end, "w", encoding="utf-8", closefd=False) as plain:
        stream = waiting_when_nonblocking(plain)
        assert stream is not plain
        got: list[bytes] = []
        reader = threading.Thread(target=lambda: got.append(_read_all(read_end)))
        reader.start()
        text = "".join(f"line {i} → é\n" for i in range(40_000))  # far more than a pipe holds
        stream.write(text)
        stream.flush()
        stream.close()
    os.close(write_end)
    reader.join(timeout=600)
    assert not reader.is_alive()
    assert got[0] == text.encode("utf-8")
    # a non-blocking terminal is a terminal still (its colour and progress bar kept)
    import pty

    leader, follower = pty.openpty()
    try:
        os.set_blocking(follower, False)
        with open(follower, "w", closefd=False) as terminal:
            assert waiting_when_nonblocking(terminal).isatty()
    finally:
        os.close(leader)
        os.close(follower)
    # and a blocking descriptor's stream is left as it is
    with open(os.devnull, "w") as blocking:
        assert waiting_when_nonblocking(blocking) is blocking
