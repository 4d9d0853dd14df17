"""A word said while another thread closes the :class:`WordsWriter` is written (by the writer
thread before it ends, or by the caller after it): never queued behind the thread's end, where
it was neither written nor counted as dropped (and its wake-up byte went to a closed
descriptor, or to whatever a later ``open()`` got that number for).

Deterministic: the saying thread is stopped inside ``write`` (as it takes the count lock, the
one hook the method has) until the closing thread has either finished the close or is waiting
on that lock; no sleeps, no timing. Before the fix the close finished and the word went to a
queue no thread read any more.
"""

from __future__ import annotations

import io
import threading
from typing import Any

import pytest

from rti_rig.cli.unwaited_words import WordsWriter

#: Far beyond what either step takes on a loaded machine: only a broken writer waits this long.
DEADLINE_S = 30.0


class _Gate:
    """An RLock standing for the writer's count lock: the saying thread's first acquire is
    held there (after the lock is taken) until ``progress`` is set; any thread that finds the
    lock taken sets ``progress`` before it waits (the close reached the lock)."""

    def __init__(self, sayer: threading.Thread | None = None) -> None:
        self._lock = threading.RLock()
        self.sayer = sayer
        self.at_gate = threading.Event()
        self.progress = threading.Event()
        self._gated = False

    def acquire(self, blocking: bool = True, timeout: float = -1) -> bool:
        if not self._lock.acquire(blocking=False):
            self.progress.set()  # someone holds it: the close is waiting on the sayer
            if not self._lock.acquire(blocking, timeout):
                return False
        if threading.current_thread() is self.sayer and not self._gated:
            self._gated = True
            self.at_gate.set()
            assert self.progress.wait(DEADLINE_S), "the close neither ended nor waited"
        return True

    def release(self) -> None:
        self._lock.release()

    def __enter__(self) -> bool:
        return self.acquire()

    def __exit__(self, *exc: Any) -> None:
        self.release()


def test_a_word_said_as_the_writer_closes_is_written() -> None:
    stream = io.StringIO()
    writer = WordsWriter(notes_to=io.StringIO())
    gate = _Gate()
    writer._count_lock = gate  # type: ignore[assignment]
    failures: list[BaseException] = []

    def say() -> None:
        try:
            writer.write(stream, "the last word\n")
        except BaseException as exc:  # reported by the test
            failures.append(exc)

    sayer = threading.Thread(target=say, name="sayer")
    gate.sayer = sayer
    sayer.start()
    assert gate.at_gate.wait(DEADLINE_S)

    def close() -> None:
        try:
            writer.close(DEADLINE_S)
        finally:
            gate.progress.set()  # the close is done (before the fix it never waited on the lock)

    closer = threading.Thread(target=close, name="closer")
    closer.start()
    sayer.join(DEADLINE_S)
    closer.join(DEADLINE_S)
    assert not sayer.is_alive() and not closer.is_alive()
    assert not failures
    assert stream.getvalue() == "the last word\n"
    assert writer.unwritten() == 0


def test_a_drain_from_a_handler_that_interrupted_a_write_is_not_stalled() -> None:
    """A signal handler (SIGTERM's wait for the words before its default action) landing while
    the main thread was inside ``write``, the count lock held: the handler's drain waits for
    the writer thread, which had to take that same lock to count each word written, and so
    wrote none until the wait gave up (2 s in the CLI, the words then lost to the default
    action). The writer thread now counts what it wrote on its own, without the lock."""
    stream = io.StringIO()
    writer = WordsWriter(notes_to=io.StringIO())
    try:
        writer.write(stream, "a word said before\n")
        with writer._count_lock:  # as the interrupted write holds it
            writer.write(stream, "the handler's word\n")  # re-entrant: the handler speaks
            assert writer.drain(DEADLINE_S), "the writer thread waited on the saying thread"
            assert writer.unwritten() == 0
        assert stream.getvalue() == "a word said before\nthe handler's word\n"
    finally:
        writer.close(DEADLINE_S)


def test_words_beyond_the_limit_are_dropped_counted_and_said() -> None:
    """The counts without the writer thread's lock still keep the limit and the note."""
    release = threading.Event()

    class Stalled(io.StringIO):
        def write(self, text: str) -> int:
            release.wait(DEADLINE_S)  # a reader that does not read until told
            return super().write(text)

    notes = io.StringIO()
    stream = Stalled()
    writer = WordsWriter(notes_to=notes, limit=10)
    try:
        writer.write(stream, "12345678\n")  # 9: held
        writer.write(stream, "abc\n")  # 9 + 4 > 10: dropped
        assert writer.unwritten() == 13
        release.set()
        assert writer.drain(DEADLINE_S)
        assert writer.unwritten() == 0
        assert stream.getvalue() == "12345678\n"
        assert "note: 4 characters of output were dropped" in notes.getvalue()
    finally:
        release.set()
        writer.close(DEADLINE_S)


class _SpokenOver(str):
    """A word whose every measuring runs ``say``: a signal handler that speaks, landing at a
    call ``write`` makes to measure it (a call is where Python runs a pending handler; which
    call a real one meets is chance, so each gets one)."""

    say: Any = None

    def __len__(self) -> int:
        if self.say is not None:
            self.say()
        return super().__len__()


@pytest.mark.parametrize("kept", [True, False], ids=["queued", "dropped"])
def test_a_handler_speaking_inside_a_write_has_its_characters_counted(kept: bool) -> None:
    """The count lock is re-entrant (a handler in the main thread must not deadlock on it), so
    it does not keep that handler out of the main thread's own ``+=``: a handler landing
    between the read of a count and its store (at ``len(text)``, measured there) had its
    characters overwritten. Queued, the held count then ran negative (``unwritten()`` below
    zero, the limit overrun by them); dropped, the note said fewer characters than were
    lost."""
    release = threading.Event()

    class Stalled(io.StringIO):
        def write(self, text: str) -> int:
            release.wait(DEADLINE_S)
            return super().write(text)

    notes, stream = io.StringIO(), Stalled()
    limit = 100 if kept else 10
    writer = WordsWriter(notes_to=notes, limit=limit)
    try:
        handlers = "Stopping after this image\n"  # 26: beyond the limit of 10 too
        spoke: list[str] = []

        def handler_speaks() -> None:
            spoke.append(handlers)
            writer.write(stream, handlers)

        word = _SpokenOver("the main thread's word\n")  # 23
        word.say = handler_speaks
        writer.write(stream, word)
        word.say = None
        said = len("".join(spoke)) + len(word)
        assert spoke and writer.unwritten() == said
        release.set()
        assert writer.drain(DEADLINE_S)
        assert writer.unwritten() == 0
        if kept:
            assert stream.getvalue() == "".join(spoke) + word
        else:
            assert f"note: {said} characters" in notes.getvalue(), notes.getvalue()
    finally:
        release.set()
        writer.close(DEADLINE_S)
