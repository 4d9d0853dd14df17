"""The words thread writes stderr's words to a copy of descriptor 2 taken as the command
began, and the RAW decoder gives back lines it caught on fd 2 through ``sys.stderr``.

Why: the decoder points fd 2 at a capture file while LibRaw reads (its lines about the file
are kept off the terminal). The words thread's words written to fd 2 then went into that
capture, one that began with the file's name taken for LibRaw's own and never said; and the
decoder wrote the lines it gave back straight to fd 2 from the main thread, mid-capture, where
a full pipe whose reader stalled held it (a DSLR's frame is decoded with the light on).
"""

from __future__ import annotations

import contextlib
import io
import os
import select
import sys
from pathlib import Path

import pytest

from rti_rig.cli.unwaited_words import UnwaitedStream, WordsWriter, _fd2_copy
from rti_rig.drivers.cameras.raw_decode import libraw_printed

NAME = "/s/raw/.incoming/IMG_1.dng"


def test_the_words_threads_words_are_not_caught_by_the_decoders_hold_on_fd_2(
    capfd: pytest.CaptureFixture[str],
) -> None:
    with open(2, "w", closefd=False) as stderr:  # the command's stderr: fd 2 as it began
        copy = _fd2_copy(stderr)
        assert copy is not None
        try:
            writer = WordsWriter(notes_to=copy)
            said = UnwaitedStream(stderr, writer, copy)
            printed: list[str] = []
            capfd.readouterr()
            with libraw_printed(NAME, printed):
                said.write(f"{NAME}: moved aside (rti-rig's word, not LibRaw's)\n")
                writer.drain()  # written while fd 2 is the decoder's capture file
                os.write(2, f"{NAME}: data corrupted at 1024\n".encode())
        finally:
            os.close(copy.fd)
    assert printed == ["data corrupted at 1024"]
    assert capfd.readouterr().err == f"{NAME}: moved aside (rti-rig's word, not LibRaw's)\n"


def test_lines_the_decoder_gives_back_go_through_sys_stderr(
    capfd: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    words = io.StringIO()  # as the console entry's stderr, which queues for its thread
    monkeypatch.setattr(sys, "stderr", words)
    capfd.readouterr()
    printed: list[str] = []
    with libraw_printed(NAME, printed):
        os.write(2, f"{NAME}: data corrupted at 1024\n".encode())
        os.write(2, b"another library's warning\n")
    assert printed == ["data corrupted at 1024"]
    assert words.getvalue() == "another library's warning\n"
    assert capfd.readouterr().err == ""  # nothing written to fd 2 from the main thread


def test_a_later_entry_closes_the_last_copy_only_after_the_word_being_written(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The thread has taken the last entry's word off the queue and waits for room in a full
    pipe: a second entry (a second ``main()`` in one process, as tests run it) must not close
    that copy under it (the word was lost, or written to a descriptor number a later
    ``open()`` took); it is closed once the word is out."""
    import fcntl
    import types

    from rti_rig.cli import unwaited_words
    from rti_rig.cli.unwaited_words import Fd2Copy, words_unwaited

    r, w = os.pipe()
    try:
        os.set_blocking(w, False)
        os.set_blocking(r, False)
        room = fcntl.fcntl(w, fcntl.F_GETPIPE_SZ)
        os.write(w, b"x" * room)  # full: the word must wait for the reader
        copy = Fd2Copy(io.StringIO(), os.dup(w))
        writer = WordsWriter(notes_to=io.StringIO())
        monkeypatch.setattr(unwaited_words, "_writer", writer)
        monkeypatch.setattr(unwaited_words, "_copy", copy)
        monkeypatch.setattr(sys, "stdout", io.StringIO())
        monkeypatch.setattr(sys, "stderr", io.StringIO())  # no descriptor: no copy of its own
        writer.write(copy, "the last word\n")
        for _ in range(60_000):  # taken off the queue by the thread (bounded, not timed)
            if not writer._items:
                break
            os.sched_yield()
        consoles = (types.SimpleNamespace(file=None), types.SimpleNamespace(file=None))
        words_unwaited(consoles)  # the next entry
        got = b""
        while len(got) < room:  # the reader comes back: the filler, then room for the word
            try:
                got += os.read(r, room)
            except BlockingIOError:
                select.select([r], [], [])
        writer.drain()  # the word written (or dropped), then the copy closed
        tail = b""
        with contextlib.suppress(BlockingIOError):
            tail = os.read(r, 4096)
        assert got[room:] + tail == b"the last word\n"
        assert copy.fd == -1  # closed, not left open
    finally:
        os.close(r)
        os.close(w)


def test_stdouts_failure_note_goes_to_the_copy_not_to_the_decoders_hold_on_fd_2(
    capfd: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """stdout's "output could not be written" note, written by the words thread as stdout's
    write fails, went straight to fd 2: while the decoder held fd 2 it landed in the capture
    and came out only after the decode (here: not yet on the command's stderr)."""
    import errno
    import importlib
    import types

    from rti_rig.cli import unwaited_words
    from rti_rig.cli.unwaited_words import words_unwaited

    app = importlib.import_module("rti_rig.cli.app")
    log = os.open(tmp_path / "log", os.O_WRONLY | os.O_CREAT)

    class DiskFull:  # a `> log` whose disk is full
        def write(self, text: str) -> int:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        def flush(self) -> None:
            pass

        def fileno(self) -> int:
            return log

    writer = WordsWriter(notes_to=io.StringIO())
    monkeypatch.setattr(unwaited_words, "_writer", writer)
    monkeypatch.setattr(unwaited_words, "_copy", None)
    try:
        with open(2, "w", closefd=False) as stderr:  # the command's stderr: fd 2 as it began
            monkeypatch.setattr(sys, "stdout", app.ReaderGoneTolerant(DiskFull(), said_on=stderr))
            monkeypatch.setattr(sys, "stderr", app.ReaderGoneTolerant(stderr))
            consoles = (types.SimpleNamespace(file=None), types.SimpleNamespace(file=None))
            words_unwaited(consoles)
            copy = unwaited_words._copy
            assert copy is not None
            try:
                capfd.readouterr()
                printed: list[str] = []
                with libraw_printed(NAME, printed):
                    sys.stdout.write("Captured 12 images\n")
                    writer.drain()  # the note written while fd 2 is the decoder's capture
                    assert "output could not be written" in capfd.readouterr().err
            finally:
                copy.close()
    finally:
        os.close(log)
    assert printed == []
