"""The console entry's words written by a thread of their own, so that no print waits on the
reader of rti-rig's output while a lamp is lit or an arm moves.

Why: stdout and stderr wait when their pipe is full (a blocking pipe always did; a non-blocking
one does since :class:`rti_rig.cli.app.WritableWaited`). A reader that stops reading (a paused
``| less``, a wedged CI runner, a node ``child_process`` nobody drains, a terminal stopped by
Ctrl-S) then blocked the print, and a print made between "light on" and "light off" (a
device's word, a warning, a signal handler's "Stopping after this image", the progress bar on a
terminal) kept the LED lit, or the arm where it was, for as long as the reader stalled: a
thermal risk for the dome and light dose on the object. The teardown's all-off could wait on a
word too (a dome reopening its port says so as it happens).

Why a queue rather than a bounded wait: any wait with the lamp lit is dose on the object, and a
wait of a few seconds repeated at each print is minutes; a word queued costs nothing. The queue
is bounded (:data:`HELD_LIMIT` characters): beyond it the words are dropped, counted, and said
to be on stderr once the reader reads again, so a reader stalled for hours (a stopped terminal
under a progress bar's redraws) cannot fill the memory. Nothing captured depends on the words:
the images, journal and manifest are written as before. At the command's end the process waits
for the reader to take what is queued (as it did before for each print), the rig then safe; a
Ctrl-C there gives the words up, says so, and exits 130 unless the command ended otherwise; a
SIGTERM or hang-up no command handles gives them up to 2 s (:func:`stops_wait_for_the_words`).
"""

from __future__ import annotations

import atexit
import collections
import contextlib
import errno
import os
import select
import signal
import sys
import threading
from typing import Any

from rti_rig.core.deferred_signals import before_default_action, default_after_hooks

#: How many characters may wait for a stalled reader before further words are dropped.
HELD_LIMIT = 1 << 20

_FLUSH = object()
_CLOSE = object()  # the thread ends here (:meth:`WordsWriter.close`)


class WordsWriter:
    """One thread writing, in the order they were said, the words of both standard streams.

    The saying side (any thread, and signal handlers in the main thread) only appends to a
    deque and writes a byte to a non-blocking wake-up pipe: nothing there can block on the
    reader. The saying side counts the characters it queued and dropped under ``_count_lock``,
    held only for the arithmetic and the queueing (never across a stream's write; the wake-up
    byte's write is non-blocking: see :meth:`_queue`), re-entrant so that a handler that speaks
    while the main thread was counting cannot deadlock; the writer thread counts what it wrote
    and said dropped in counters of its own, so it never takes that lock: the held count is
    the difference (``+=`` from the saying threads and ``-=`` from the writer thread on one
    count had raced, and it drifted: words dropped below the limit, or the limit overrun). One
    queue for both streams keeps their order (``2>&1``) as it was said.

    Why the writer thread takes no lock: a signal handler that waits for the words (SIGTERM's
    or a hang-up's, before the default action) can land while the main thread is inside
    :meth:`write`, the lock held; the writer thread, taking it to count each word written,
    wrote none until the wait gave up, and the words were lost to the default action."""

    def __init__(self, notes_to: Any, limit: int = HELD_LIMIT) -> None:
        self._items: collections.deque[Any] = collections.deque()
        self._limit = limit
        self._count_lock = threading.RLock()
        # saying side, under ``_count_lock``: characters queued, characters dropped
        self._queued = 0
        self._dropped = 0
        # writer thread only, no lock: characters written (or lost), dropped and said so
        self._written = 0
        self._dropped_said = 0
        self._closed = False
        self.notes_to = notes_to
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_w, False)
        self._thread = threading.Thread(target=self._run, name="rti-rig words", daemon=True)
        self._thread.start()

    def write(self, stream: Any, text: str) -> None:
        # measured before any count is read: each ``+=`` below then has no call between its
        # read and its store, where a signal handler that speaks (the lock is re-entrant: it
        # does not keep the main thread's own handler out) would have its count overwritten
        n = len(text)
        with self._count_lock:  # the check and the queueing as one against close()
            if self._open():
                if self._queued - self._written + n > self._limit:
                    self._dropped += n
                    return
                self._queued += n
                self._queue((stream, text))
                return
        stream.write(text)  # a forked child, a closed writer: as before

    def flush(self, stream: Any) -> None:
        with self._count_lock:
            if self._open():
                self._queue((stream, _FLUSH))
                return
        stream.flush()

    def _open(self) -> bool:
        """Whether the thread takes what is queued now; under ``_count_lock`` (see
        :meth:`_queue`)."""
        return not self._closed and self._thread.is_alive()

    def _queue(self, item: Any) -> None:
        """Queue ``item`` and wake the thread; under ``_count_lock``, :meth:`_open` checked
        under the same hold.

        Why: checked before the lock, a word said as another thread closed the writer could
        be queued after the close's end mark, once the thread had passed it and ended: neither
        written nor counted as dropped (its characters counted held for ever), and its wake-up
        byte written to a descriptor the close had closed, or that a later ``open()`` got.
        :meth:`close` sets ``_closed`` and queues its mark under the lock: a word is queued
        before the mark (written by the thread) or finds the writer closed (written here)."""
        self._items.append(item)
        self._wake()

    def drain(self, timeout: float | None = None) -> bool:
        """Wait until every word said so far is written (or dropped by a gone reader), at
        most ``timeout`` seconds if given; whether they were."""
        if not self._thread.is_alive() or threading.current_thread() is self._thread:
            return True
        if self._closed:  # nothing queued now would be taken: the thread's end is the wait
            self._thread.join(timeout)
            return not self._thread.is_alive()
        done = threading.Event()
        with self._count_lock:
            queued = self._open()
            if queued:
                self._queue(done)
        if not queued:  # closed meanwhile: the thread's end is the wait (out of the lock,
            self._thread.join(timeout)  # which the thread takes as it writes)
            return not self._thread.is_alive()
        return done.wait(timeout)

    def unwritten(self) -> int:
        """How many characters said are not written: queued for the reader, or dropped and
        not yet said to be."""
        # each count only grows, and the writer's trail the sayers': the writer's read first,
        # the difference is never below what is unwritten (read after, it could be negative)
        written, said = self._written, self._dropped_said
        with self._count_lock:
            queued, dropped = self._queued, self._dropped
        return queued - written + dropped - said

    def close(self, timeout: float | None = None) -> bool:
        """Let the thread write what is queued, then end it and close its wake-up pipe, at
        most ``timeout`` seconds waited for; whether it ended. Words said after this are
        written by the caller, as without a writer.

        Why: each writer kept a thread and two descriptors for the rest of the process; a
        program or test that makes writers of its own had no way to give them back. Where the
        thread does not end in time (a stalled reader), its pipe is left open for it."""
        with self._count_lock:  # no word queued after the mark (see :meth:`_queue`)
            if not self._closed:
                self._closed = True
                self._queue(_CLOSE)
        if threading.current_thread() is self._thread:
            return False
        self._thread.join(timeout)
        if self._thread.is_alive():
            return False
        with self._count_lock:  # closed once: a second close() never closes a number reused
            fds, self._wake_r, self._wake_w = (self._wake_r, self._wake_w), -1, -1
        for fd in fds:
            if fd >= 0:
                with contextlib.suppress(OSError):
                    os.close(fd)
        return True

    def _wake(self) -> None:
        with contextlib.suppress(OSError):  # full: the thread is awake already
            os.write(self._wake_w, b"\0")

    def _run(self) -> None:
        closing = False
        while not closing:
            os.read(self._wake_r, 4096)
            while self._items:
                item = self._items.popleft()
                if item is _CLOSE:  # ends once what came in meanwhile is written too
                    closing = True
                    continue
                if isinstance(item, threading.Event):  # a drain: the note before its end
                    if self._dropped != self._dropped_said:
                        self._say_dropped()
                    item.set()
                    continue
                stream, text = item
                try:
                    if text is _FLUSH:
                        stream.flush()
                    else:
                        try:
                            stream.write(text)
                        finally:  # counted until written: a word a stalled reader holds
                            self._written += len(text)  # is not yet written
                except Exception:  # a word lost, never the writer
                    pass
                if not self._items and self._dropped != self._dropped_said:
                    self._say_dropped()

    def _say_dropped(self) -> None:
        total = self._dropped  # read once: a later drop is said at the next note
        dropped, self._dropped_said = total - self._dropped_said, total
        with contextlib.suppress(Exception):
            self.notes_to.write(
                f"note: {dropped} characters of output were dropped: its reader did not read "
                f"for so long that over {self._limit} waited for it (rti-rig does not wait on "
                "its reader while the rig works); the session's files hold what happened\n"
            )
            self.notes_to.flush()


class UnwaitedStream:
    """A standard stream whose writes and flushes go through a :class:`WordsWriter`, to
    ``target`` (the stream itself unless given: stderr's :class:`Fd2Copy`)."""

    def __init__(self, stream: Any, writer: WordsWriter, target: Any = None) -> None:
        self._stream = stream
        self._writer = writer
        self._target = stream if target is None else target

    def write(self, text: str) -> int:
        self._writer.write(self._target, text)
        return len(text)

    def flush(self) -> None:
        self._writer.flush(self._target)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


class Fd2Copy:
    """Where the writer thread writes stderr's words: a copy (``os.dup``) of descriptor 2
    taken as the console entry began, in the encoding and error handling of the stream it
    stands for; a full non-blocking pipe is waited on (the writer thread may wait: that is
    what it is for), a failed write raised to the writer, which drops the word.

    Why: descriptor 2 is pointed elsewhere for a moment by code that captures what C
    libraries print there (the RAW decoder holds LibRaw's lines off the terminal while it
    reads a file); the writer thread's words written to fd 2 meanwhile went into that capture
    and came out later, out of order, or were taken for the library's own. The copy still
    names the terminal or pipe the command was given."""

    def __init__(self, stream: Any, fd: int) -> None:
        self.fd = fd
        self._encoding = getattr(stream, "encoding", None) or "utf-8"
        self._errors = getattr(stream, "errors", None) or "backslashreplace"

    def write(self, text: str) -> int:
        if self.fd < 0:  # closed: never a write to a number a later open() may have taken
            raise OSError(errno.EBADF, "the copy of descriptor 2 is closed")
        data = memoryview(text.encode(self._encoding, self._errors))
        while data:
            try:
                written = os.write(self.fd, data)
            except BlockingIOError:  # a pipe its reader set non-blocking: wait for room
                select.select([], [self.fd], [])
                continue
            except InterruptedError:
                continue
            data = data[written:]
        return len(text)

    def flush(self) -> None:
        """Nothing is buffered: each word is written as it comes."""

    def close(self) -> None:
        """Close the copy; a later write through it fails (the writer drops that word)."""
        fd, self.fd = self.fd, -1
        if fd >= 0:
            with contextlib.suppress(OSError):
                os.close(fd)


class _ClosedInTurn:
    """A :class:`Fd2Copy` closed by the writer thread once the words queued before this
    (``flush`` of it queued as any flush is) are written.

    Why: closed by the next console entry as soon as the queue looked empty, the copy could
    be closed while the thread wrote its last word (taken off the queue, waiting in
    ``select`` for a full pipe's room): the word was lost, or written to whatever a later
    ``open()`` got that descriptor number for; and with words still queued it was never
    closed."""

    def __init__(self, copy: Fd2Copy) -> None:
        self._copy = copy

    def flush(self) -> None:
        self._copy.close()


def _fd2_copy(stderr: Any) -> Fd2Copy | None:
    """A :class:`Fd2Copy` for ``stderr`` where it writes to descriptor 2 (after a flush of
    what it holds, so that the order is kept), else None (a stream of no descriptor, or of
    another one: nothing swaps it)."""
    try:
        if stderr.fileno() != 2:
            return None
        stderr.flush()
        return Fd2Copy(stderr, os.dup(2))
    except (AttributeError, OSError, ValueError):
        return None


_writer: WordsWriter | None = None
#: the descriptor 2 copy the current entry's stderr words are written to (closed once a later
#: entry takes its own and no word is left queued for it)
_copy: Fd2Copy | None = None


def words_unwaited(consoles: tuple[Any, Any]) -> None:
    """Give ``sys.stdout``/``sys.stderr`` and the consoles (``out``, ``err``) their streams
    through one :class:`WordsWriter`; the console entry only (as the tolerant streams)."""
    global _writer, _copy
    out, err = consoles
    stdout, stderr = sys.stdout, sys.stderr
    if _writer is None:  # one thread a process; each entry's streams are its own
        _writer = WordsWriter(notes_to=stderr)
        atexit.register(words_written)  # a Ctrl-C there changes no exit status: main's does
        before_default_action.append(words_written_before_signal)
    copy = _fd2_copy(stderr)  # stderr's words never land where fd 2 is pointed for a moment
    if _copy is not None:  # the last entry's: closed by the thread after its queued words
        _writer.flush(_ClosedInTurn(_copy))
    _copy = copy
    _writer.notes_to = stderr if copy is None else copy
    if copy is not None:  # stdout's failure note, written by the thread: to the copy too
        from rti_rig.cli.app import ReaderGoneTolerant  # app imports this module when it runs

        if isinstance(stdout, ReaderGoneTolerant):
            stdout.say_failure_on(copy)
    sys.stdout = out.file = UnwaitedStream(stdout, _writer)  # type: ignore[assignment]
    sys.stderr = err.file = UnwaitedStream(stderr, _writer, copy)  # type: ignore[assignment]


def words_written() -> bool:
    """Wait for the reader to take every word said (the command's end: the rig is safe);
    False if a Ctrl-C ended the wait (now or earlier), the words left unwritten.

    A Ctrl-C during the wait ends it, and every later one (the exit's): the user chose to
    leave the words a stalled reader never took. How many is said on stderr where it can be
    without a wait (:func:`_say_now`), and the caller exits as a Ctrl-C does (130), not as
    the command did: the words it said were not all written, and a ``0`` had claimed a
    success the reader never saw."""
    global _given_up
    if _writer is None:
        return True
    if _given_up:
        return False
    try:
        _writer.drain()
    except KeyboardInterrupt:
        _given_up = True
        _say_now(
            f"rti-rig: stopped waiting for the output's reader (Ctrl-C): {_writer.unwritten()} "
            "characters of output were not written\n"
        )
        return False
    return True


def _say_now(text: str) -> None:
    """Write ``text`` to stderr's descriptor (the console entry's copy of it) only if that
    can be done without waiting: a pipe with room, a terminal, a file; else it is dropped
    (stderr is the stalled reader's own pipe: the exit status still says the stop).

    Why not through the writer: its thread is blocked on the stalled reader, and the words
    queued behind it are exactly the ones given up."""
    fd = _copy.fd if _copy is not None else 2
    with contextlib.suppress(OSError, ValueError):
        if select.select([], [fd], [], 0)[1]:
            os.write(fd, text.encode("utf-8", "backslashreplace"))


#: A Ctrl-C ended a wait for the reader: the process no longer waits for it.
_given_up = False

#: How long the words may be waited on before a signal's default action ends the process.
#: Long enough for a reader that reads at all to take the whole queue (:data:`HELD_LIMIT`
#: is written in milliseconds), short beside a supervisor's grace before its SIGKILL
#: (``docker stop``'s 10 s): a stalled reader does not hold the stop up for long.
BEFORE_DEFAULT_ACTION_S = 2.0


def words_written_before_signal() -> None:
    """Wait up to :data:`BEFORE_DEFAULT_ACTION_S` for the queued words to be written, before
    a signal's default action ends the process (registered with the core's
    ``before_default_action``: it calls this only where the rig is safe).

    Why: the default action ends the process at once; the words still queued (the last lines
    of a summary, a stop's words) were lost, where each print had been written before it
    returned. A Ctrl-C during the wait ends the wait, the signal still acted on."""
    if _writer is None or _given_up:
        return
    with contextlib.suppress(KeyboardInterrupt):
        _writer.drain(BEFORE_DEFAULT_ACTION_S)


def stops_wait_for_the_words() -> None:
    """Where SIGTERM's action, or a hang-up's (SIGHUP), is the default as the console entry
    begins, answer it with the core's
    :func:`~rti_rig.core.deferred_signals.default_after_hooks`: the default action, after up
    to :data:`BEFORE_DEFAULT_ACTION_S` for the words already said. A command that sets its own
    handler (``run``, ``check``, ``probe`` while it works; ``fit`` and ``plan`` while they
    write; a hang-up answered as their SIGTERM) puts this one back as it ends. Main thread
    only; a signal ignored (``nohup``) or handled outside Python is left as it is.

    Why: ``bench`` has no SIGTERM handler, ``fit`` and ``plan`` none once their work is done,
    and no command one in the end's wait for the words: a SIGTERM there (``timeout``, a
    scheduler) ended the process at once and the words still queued for a slow reader (a
    summary, a stop's words, a help text) were lost. None of those moments holds hardware
    (``probe`` has closed its dome by then), so a wait of 2 s at most costs no safety.

    Why the hang-up too: it is the terminal or the ssh connection closing, and it had ended
    those same moments at once (``bench --help`` into a busy pipe lost its whole text, where a
    SIGTERM's waited for it). Words bound for the terminal that hung up cost nothing to wait
    for (a write to a hung-up terminal fails at once; the writer drops the word), and words
    bound for a file or a pipe (``> log``, ``| tee log``) are what the user will read; the
    process still ends by SIGHUP (exit 129)."""
    if threading.current_thread() is not threading.main_thread():
        return
    for sig in (signal.SIGTERM, getattr(signal, "SIGHUP", None)):
        if sig is not None and signal.getsignal(sig) == signal.SIG_DFL:
            signal.signal(sig, default_after_hooks)


def say_unwaited(text: str) -> None:
    """Say ``text`` on stderr from a signal handler, never waiting on the reader where the
    words are queued (the console entry); else written to descriptor 2 as before, a write that
    fails (a full non-blocking pipe: ``BlockingIOError``) dropped rather than raised into the
    teardown the handler interrupted."""
    if _writer is not None:
        sys.stderr.write(text)
        sys.stderr.flush()
        return
    with contextlib.suppress(OSError):
        os.write(2, text.encode("utf-8", "replace"))
