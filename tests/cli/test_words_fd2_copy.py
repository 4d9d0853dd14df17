"""The words thread writes stderr's words to a copy of descriptor 2 taken as the command
began, and the RAW decoder gives back lines it caught on fd 2 through ``sys.stderr``.

Why: the decoder points fd 2 at a capture file while LibRaw reads (its lines about the file
are kept off the terminal). The words thread's words written to fd 2 then went into that
capture, one that began with the file's name taken for LibRaw's own and never said; and the
decoder wrote the lines it gave back straight to fd 2 from the main thread, mid-capture, where
a full pipe whose reader stalled held it (a DSLR's frame is decoded with the light on).
"""

from __future__ import annotations

import io
import os
import sys

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
