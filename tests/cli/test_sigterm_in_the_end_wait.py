"""A SIGTERM while a command with no SIGTERM handler of its own (``plan``'s help here; ``fit``,
``plan`` and ``bench`` once their work is done, ``probe`` once its dome is closed) waits at
its end for a stalled reader: the words said before the signal still reach the reader, and
the process ends by SIGTERM (143 in a shell).

Before, SIGTERM's default action ended the process at once and the words queued for the
reader were lost (the writer thread, not the print, held them). Through ``python -m rti_rig``
on a real one-page pipe filled before the command starts; the signal is sent once /proc shows
the command at its end (the main thread waiting, the words thread blocked writing to the
pipe), and the reader reads as soon as it is sent. The wait for the words, 2 s in a real stop
(``BEFORE_DEFAULT_ACTION_S``), is 600 s in the child, as in test_words_before_default_action:
the reader begins only after the signal, and a loaded CI runner may take longer than 2 s to
start it, which lost the words with the wait in place (a failure that said nothing).

And a Ctrl-C in that wait ends it with the interrupt's exit status (130) and says, where
stderr has room, how much output was not written: the command had exited 0 (its own status),
claiming a success whose words the reader never got.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time

import pytest
from conftest import ended_on_exit, full_pipe, rti_rig_on_pipe

pytestmark = pytest.mark.skipif(
    not sys.platform.startswith("linux"), reason="needs Linux's F_SETPIPE_SZ and /proc"
)


def _wchans(pid: int) -> dict[int, str]:
    """What each thread of ``pid`` waits on in the kernel, by thread id (main thread: pid)."""
    found: dict[int, str] = {}
    try:
        tids = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return found
    for tid in tids:
        try:
            with open(f"/proc/{pid}/task/{tid}/wchan") as wchan:
                found[int(tid)] = wchan.read()
        except OSError:
            pass
    return found


def _at_its_end(pid: int) -> bool:
    """Whether ``pid`` has said its words and waits for them: its main thread waits on a lock
    (the end's wait for the words thread: a futex) while another thread is blocked writing
    to the full pipe."""
    wchans = _wchans(pid)
    main = wchans.pop(pid, "")
    return "futex" in main and any("pipe_write" in w for w in wchans.values())


def _wait_at_its_end(command: subprocess.Popen[bytes]) -> None:
    """Return once ``command`` is at its end (:func:`_at_its_end`), however long a loaded
    machine takes (up to 600 s); fail if it ends first."""
    deadline = time.monotonic() + 600
    while not _at_its_end(command.pid):
        assert command.poll() is None, "the command ended with its reader stalled"
        assert time.monotonic() < deadline, "the command did not reach its end in 600 s"
        time.sleep(0.05)


#: ``python -m rti_rig plan --help`` with the wait for the words bounded at 600 s, not 2 s.
_PLAN_HELP_UNHURRIED = r"""
import sys
from rti_rig.cli import unwaited_words
unwaited_words.BEFORE_DEFAULT_ACTION_S = 600.0
sys.argv = ["rti-rig", "plan", "--help"]
from rti_rig.launch import main
main()
"""


def test_a_sigterm_in_the_end_wait_keeps_the_words_said_and_ends_by_sigterm() -> None:
    read_end, write_end, filler = full_pipe(writer_blocking=True)
    command = rti_rig_on_pipe(["-c", _PLAN_HELP_UNHURRIED], write_end)
    said: list[bytes] = []
    reader = threading.Thread(target=lambda: said.append(os.fdopen(read_end, "rb").read()))
    with ended_on_exit(command):
        _wait_at_its_end(command)
        command.send_signal(signal.SIGTERM)
        reader.start()  # the words are waited on (600 s here) once the signal is handled
        code = command.wait(timeout=600)
        reader.join(timeout=600)
    assert said[0].startswith(filler)
    words = said[0][len(filler) :].decode("utf-8", "replace")
    assert "Usage:" in words and "--rig" in words and "--out" in words, words
    assert "Traceback" not in words, words
    assert code == -signal.SIGTERM, (code, words)


def test_a_ctrl_c_in_the_end_wait_says_the_words_unwritten_and_exits_130() -> None:
    read_end, write_end, _filler = full_pipe(writer_blocking=True)
    # stdout the stalled reader (``| less`` paused), stderr a terminal's, read throughout
    command = rti_rig_on_pipe(["-m", "rti_rig", "plan", "--help"], write_end, subprocess.PIPE)
    assert command.stderr is not None
    errors = command.stderr
    said: list[bytes] = []
    reader = threading.Thread(target=lambda: said.append(errors.read()))
    reader.start()
    with ended_on_exit(command), os.fdopen(read_end, "rb"):
        _wait_at_its_end(command)
        command.send_signal(signal.SIGINT)
        code = command.wait(timeout=600)  # the stdout reader never reads
        reader.join(timeout=600)
    words = said[0].decode("utf-8", "replace")
    assert code == 130, (code, words)
    assert "stopped waiting for the output's reader (Ctrl-C)" in words, words
    assert "characters of output were not written" in words, words
    assert "Traceback" not in words, words


def test_a_ctrl_c_in_the_end_wait_keeps_a_failed_commands_exit() -> None:
    """A command that ended with its own failure (a usage error's 2) keeps it: a Ctrl-C in
    the wait for its words claims no success it could belie."""
    read_end, write_end, _filler = full_pipe(writer_blocking=True)
    command = rti_rig_on_pipe(["-m", "rti_rig", "plan", "--no-such-option"], write_end)
    with ended_on_exit(command), os.fdopen(read_end, "rb"):
        _wait_at_its_end(command)
        command.send_signal(signal.SIGINT)
        code = command.wait(timeout=600)
    assert code == 2
