"""A reader of rti-rig's output that stops reading (a paused ``| less``, a wedged CI runner, a
node ``child_process`` nobody drains) never keeps a lamp lit: the session's capture and its
teardown (all-off) happen while the pipe stays full, and the command waits for its reader only
once the rig is safe, then says every word and ends normally.

A print had blocked on the full pipe wherever it was made, between "light on" and "light off"
too (a device's word, a warning, a signal's "Stopping after this image"): the LED stayed lit
for as long as the reader stalled. Through ``python -m rti_rig`` on a real pipe, made small
and filled before the command starts, so that its very first word finds no room.
"""

from __future__ import annotations

import json
import os
import sys
import threading
import time
from pathlib import Path

import pytest
from conftest import CONFIGS, full_pipe, rti_rig_on_pipe, unread_in_pipe

pytestmark = pytest.mark.skipif(
    not sys.platform.startswith("linux"), reason="needs Linux's F_SETPIPE_SZ and /proc"
)


def _main_thread_waits_on_pipe(pid: int) -> bool:
    """Whether the process's main thread is blocked writing to a pipe (the kernel's
    ``pipe_write``, ``anon_pipe_write`` on newer kernels): a print waiting on its reader."""
    try:
        with open(f"/proc/{pid}/wchan") as wchan:
            return "pipe_write" in wchan.read()
    except OSError:
        return False


def _finished(manifest: Path) -> dict | None:  # type: ignore[type-arg]
    """The manifest's ``runner`` once the run's teardown has recorded its end (written after
    the all-off), else None."""
    try:
        runner = json.loads(manifest.read_text()).get("runner", {})
    except (OSError, ValueError):
        return None
    return runner if runner.get("state") == "finished" else None


def test_a_run_whose_reader_stalls_switches_its_lamp_off_then_waits(tmp_path: Path) -> None:
    session = tmp_path / "session"
    read_end, write_end, filler = full_pipe(writer_blocking=True)
    config = str(CONFIGS / "simulated_dome.toml")
    # ``2>&1 | less``: every word, the device's and the warnings too
    run = ["-m", "rti_rig", "run", config, "--out", str(session), "--lights", "4"]
    command = rti_rig_on_pipe(run, write_end, columns=None)
    said: list[bytes] = []
    reader = threading.Thread(target=lambda: said.append(os.fdopen(read_end, "rb").read()))
    try:
        # Wait on the session's record of its end (written after the all-off), however long
        # a loaded machine takes; a print that waits on the full pipe is seen as it happens
        # (the main thread blocked in the kernel's pipe_write), not guessed from a timeout.
        deadline = time.monotonic() + 600
        runner = None
        while runner is None:
            runner = _finished(session / "manifest.json")
            assert not _main_thread_waits_on_pipe(command.pid) or runner is not None, (
                "rti-rig's main thread waits on its stalled reader before its session ended"
            )
            assert command.poll() is None, "the command ended with its reader stalled"
            assert time.monotonic() < deadline, "no end of the session recorded in 600 s"
            time.sleep(0.05)
        # the lights were made safe (no teardown failure) while nothing had been read
        assert runner["finish_reason"] == "completed", runner
        assert runner["teardown_failures"] == [], runner
        assert runner["steps_done_this_run"] == 4, runner
        assert unread_in_pipe(read_end) == len(filler)
        assert command.poll() is None  # its words still wait for the reader
        reader.start()  # the reader reads again: every word comes, and the command ends
        code = command.wait(timeout=600)
        reader.join(timeout=600)
    finally:
        if command.poll() is None:
            command.kill()
            command.wait()
    assert not reader.is_alive()
    words = said[0][len(filler) :].decode("utf-8", "replace")
    assert said[0].startswith(filler)
    assert code == 0, words
    assert "4 image(s) in the session" in words and "QA verdict" in words, words
    assert "dropped" not in words and "Traceback" not in words, words
    assert len(list(session.glob("image_*.jpg"))) == 4


def test_words_said_to_a_stalled_reader_never_wait_and_past_the_limit_are_dropped_and_said() -> (
    None
):
    """The saying side never writes (no write in the caller's thread, however stalled the
    reader); the words keep their order; past the limit they are dropped, and a note counting
    them is said once the reader reads again, after the words kept."""
    from rti_rig.cli.unwaited_words import WordsWriter

    room = threading.Event()
    written_by: list[threading.Thread] = []
    got: list[str] = []

    class Stalled:
        def write(self, text: str) -> int:
            written_by.append(threading.current_thread())
            room.wait(600)
            got.append(text)
            return len(text)

        def flush(self) -> None:
            written_by.append(threading.current_thread())

    stream = Stalled()
    writer = WordsWriter(notes_to=stream, limit=100)
    words = [f"word {i:02}\n" for i in range(40)]  # 360 characters, the limit 100
    for word in words:
        writer.write(stream, word)
        writer.flush(stream)
    assert not room.is_set() and not got  # all said while nothing could be written
    room.set()
    writer.drain()
    assert threading.current_thread() not in written_by
    *kept, note = got
    assert kept == words[: len(kept)] and 10 <= len(kept) < len(words), got
    dropped = sum(map(len, words[len(kept) :]))
    assert note.startswith(f"note: {dropped} characters of output were dropped"), note
