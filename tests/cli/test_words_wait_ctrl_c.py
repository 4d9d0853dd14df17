"""A Ctrl-C while the finished command waits for a stalled reader ends that wait, and the
exit's wait too (d15fbd58): the user chose to leave the words the reader never took.

Before, the KeyboardInterrupt went through the command's wait and the exit's wait (atexit)
began again, waiting on the same stalled reader for a second Ctrl-C. In process: a words
writer whose stream never takes its word, the Ctrl-C sent to the main thread while it waits.
"""

from __future__ import annotations

import os
import signal
import threading
from typing import Any

import pytest

from rti_rig.cli import unwaited_words
from rti_rig.cli.unwaited_words import WordsWriter, words_written


class _Stalled:
    """A stream whose reader never reads (until the test ends): its first write waits."""

    def __init__(self) -> None:
        self.blocked = threading.Event()
        self.room = threading.Event()

    def write(self, text: str) -> int:
        self.blocked.set()
        self.room.wait(600)
        return len(text)

    def flush(self) -> None:
        pass


def test_a_ctrl_c_in_the_wait_for_a_stalled_reader_ends_it_and_the_exits_wait(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    stream = _Stalled()
    writer = WordsWriter(notes_to=stream)
    monkeypatch.setattr(unwaited_words, "_writer", writer)
    monkeypatch.setattr(unwaited_words, "_given_up", False, raising=False)
    writer.write(stream, "a word its reader never takes\n")
    assert stream.blocked.wait(600)  # the writer thread waits on the reader
    ended = threading.Event()  # the command's wait returned

    def ctrl_c(signum: int, frame: Any) -> None:
        if not ended.is_set():  # a late one, once the wait ended, changes nothing here
            raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, ctrl_c)

    def press_ctrl_c() -> None:  # until the wait ends (one landing before the wait: again)
        while not ended.is_set():
            signal.pthread_kill(threading.main_thread().ident or 0, signal.SIGINT)
            ended.wait(0.05)

    presser = threading.Thread(target=press_ctrl_c)
    escaped = 0
    try:
        for attempt in range(100):
            try:
                if attempt == 0:
                    presser.start()  # in the try: a Ctrl-C may land as it starts
                words_written()  # the command's wait: a Ctrl-C ends it
                break
            except KeyboardInterrupt:  # went through the wait (or landed before it began)
                escaped += 1
        else:
            raise AssertionError(f"{escaped} Ctrl-C went through the wait for the reader")
        ended.set()
        presser.join(600)
        # the exit's wait (atexit): no second Ctrl-C is needed, and none is sent now
        exits_wait = threading.Thread(target=words_written, daemon=True)
        exits_wait.start()
        exits_wait.join(120)
        assert not exits_wait.is_alive(), "the exit's wait waited on the stalled reader again"
    finally:
        ended.set()
        if presser.is_alive():
            presser.join(600)
        signal.signal(signal.SIGINT, previous)
        stream.room.set()  # the reader reads again: the writer thread ends its word


def test_a_closed_writer_writes_what_was_queued_ends_its_thread_and_writes_later_words_itself() -> (
    None
):
    """close(): the words queued before it are written by the thread, which then ends (its
    wake-up pipe closed); a word said after it is written by the caller. Before, a writer
    kept its thread and two descriptors for the rest of the process."""
    got: list[tuple[str, threading.Thread]] = []

    class Stream:
        def write(self, text: str) -> int:
            got.append((text, threading.current_thread()))
            return len(text)

        def flush(self) -> None:
            pass

    stream = Stream()
    writer = WordsWriter(notes_to=stream)
    wake_r = writer._wake_r
    for i in range(3):
        writer.write(stream, f"word {i}\n")
    assert writer.close(600)
    assert not writer._thread.is_alive()
    writer.write(stream, "after\n")
    assert [text for text, _ in got] == ["word 0\n", "word 1\n", "word 2\n", "after\n"]
    assert got[-1][1] is threading.current_thread()
    assert all(by is not threading.current_thread() for _, by in got[:3])
    assert writer.unwritten() == 0
    with pytest.raises(OSError):
        os.fstat(wake_r)
