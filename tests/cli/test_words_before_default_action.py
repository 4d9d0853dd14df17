"""The words still queued for a slow reader are written before a signal's default action
ends the process, where the rig is safe at that point: a hang-up where SIGTERM's action is
the default (before a run opens its rig), a second SIGTERM while a run's summary prints, and
a SIGTERM after the capture answered as before it (the default action).

Before, the default action ended the process at once and the words the writer thread still
held were lost (7eababb4 gave every word to that thread). Deterministic: the child queues far
more than a pipe holds while the test does not read; the child says it has reached the
default action (a hook run just before the wait for the words) and only then is all read.
The wait is bounded at 600 s in the child, so with the wait in place every word is read
whatever the load; without it the words are lost in nearly every run (a few may slip out
while the signal is raised: not a test that can pass wrongly, one that could miss a break).
"""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys

import pytest
from conftest import ended_on_exit

#: Lines of 2000 characters: ~400 KiB, far beyond a pipe's 64 KiB, under the 1 MiB held limit.
LINES = 200

_CHILD = r"""
import os, signal, sys
import importlib
from rti_rig.cli import unwaited_words
app = importlib.import_module("rti_rig.cli.app")
from rti_rig.core import deferred_signals

app.reader_gone_tolerated()
unwaited_words.words_unwaited((app.out, app.err))
# the wait bounded generously here: the test reads only once this process is in it
unwaited_words.BEFORE_DEFAULT_ACTION_S = 600.0
ready = int(sys.argv[2])

def reached() -> None:  # run before the wait for the words: the reader may read now
    os.write(ready, b"r")  # left open (closed as the process ends): no GIL given up after it

deferred_signals.before_default_action.insert(0, reached)
for i in range(LINES):  # through the streams the consoles write to (rich is slow at this size)
    stream = sys.stderr if i % 2 else sys.stdout
    stream.write(f"word {i:05d} " + "x" * 1989 + "\n")
app.err.print("a console's word", markup=False)
# the writer thread is given the GIL only as the main thread waits (the wait for the words):
# without that wait, nearly every run ends with the words queued as the reader begins
sys.setswitchinterval(1000.0)
path = sys.argv[1]
if path == "hangup":  # a hang-up answered as SIGTERM is, whose action is the default
    with deferred_signals.hangup_as_sigterm():
        signal.raise_signal(signal.SIGHUP)
elif path == "summary":
    from rti_rig.cli.session import _late_term_held
    with _late_term_held():
        signal.raise_signal(signal.SIGTERM)  # held: the summary goes on
        signal.raise_signal(signal.SIGTERM)  # asked twice: the default action
elif path == "as_before":
    from rti_rig.cli.session import _as_before
    _as_before(signal.SIG_DFL, signal.SIGTERM, None)
print("the signal did not end the process", file=sys.stderr)
""".replace("LINES", str(LINES))


def _wait_ready(ready_r: int, process: subprocess.Popen[bytes]) -> None:
    """Wait (at most 600 s, as the child's own wait) for the child's word that it is at the
    default action, or its end (EOF); closes ``ready_r``. A child that neither says it nor ends
    is ended and the test fails with what it said: it waits for a reader this test has not
    yet become, so an unbounded read here hung the whole suite (a signal that never came: the
    suite run under ``nohup``, SIGHUP inherited ignored, before conftest undid that)."""
    try:
        if not select.select([ready_r], [], [], 600.0)[0]:
            process.kill()
            said, _ = process.communicate(timeout=60)
            pytest.fail(
                "the child neither reached the default action nor ended in 600 s; it said "
                f"{said.decode(errors='replace')[-300:]!r}"
            )
        os.read(ready_r, 1)
    finally:
        os.close(ready_r)


@pytest.mark.parametrize("path", ["hangup", "summary", "as_before"])
def test_queued_words_are_written_before_a_signals_default_action(path: str) -> None:
    ready_r, ready_w = os.pipe()
    try:
        process = subprocess.Popen(
            [sys.executable, "-c", _CHILD, path, str(ready_w)],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            pass_fds=(ready_w,),
        )
    finally:
        os.close(ready_w)
    with ended_on_exit(process):
        _wait_ready(ready_r, process)  # the child is at the default action (or ended: EOF)
        said, _ = process.communicate(timeout=600)
    text = said.decode()
    missing = [i for i in range(LINES) if f"word {i:05d} " not in text]
    assert not missing, f"{len(missing)} lines lost, first {missing[:3]}; tail {text[-300:]!r}"
    assert "a console's word" in text
    assert "did not end the process" not in text
    assert process.returncode == -(signal.SIGHUP if path == "hangup" else signal.SIGTERM)


#: ``python -c`` source of the console entry (``rti_rig.launch``) running ``bench --help``
#: with its stdout a pipe it has filled itself (a reader that does not read: the help text
#: stays queued), and a hang-up (SIGHUP) as it ends, before its wait for the words. It says
#: when it reaches the default action's wait (a hook run just before it), as above.
_HANGUP_AT_THE_END = r"""
import os, signal, sys
from rti_rig.cli import unwaited_words
from rti_rig.core import deferred_signals

unwaited_words.BEFORE_DEFAULT_ACTION_S = 600.0  # the test reads only once this is waited in
ready = int(sys.argv[1])
deferred_signals.before_default_action.insert(0, lambda: os.write(ready, b"r"))
os.set_blocking(1, False)
for size in (4096, 1):  # full to the last byte: nothing more goes out until the test reads
    try:
        while True:
            os.write(1, b"f" * size)
    except BlockingIOError:
        pass
os.set_blocking(1, True)
real_written = unwaited_words.words_written

def words_written():  # the command's end, its words queued: the terminal closes
    signal.raise_signal(signal.SIGHUP)
    return real_written()

unwaited_words.words_written = words_written
sys.argv = ["rti-rig", "bench", "--help"]
from rti_rig.launch import main
main()
"""


def test_a_hang_up_as_a_command_ends_waits_for_its_words_then_ends_by_sighup() -> None:
    """``bench --help`` (no handler of its own) hung up as it ends: its help text, queued for
    a pipe, is written before the process ends by SIGHUP. Before, SIGHUP's default action
    ended it at once and the text was lost (where a SIGTERM's waited for it)."""
    ready_r, ready_w = os.pipe()
    try:
        process = subprocess.Popen(
            [sys.executable, "-c", _HANGUP_AT_THE_END, str(ready_w)],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            pass_fds=(ready_w,),
            env={**os.environ, "COLUMNS": "100"},
        )
    finally:
        os.close(ready_w)
    with ended_on_exit(process):
        _wait_ready(ready_r, process)  # the child is at the default action's wait (or ended)
        said, _ = process.communicate(timeout=600)
    text = said.decode(errors="replace").lstrip("f")
    assert "Benchmarks: the speed/accuracy trade" in text, text[-500:]
    assert process.returncode == -signal.SIGHUP, text[-500:]
