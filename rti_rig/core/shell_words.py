"""Paths as a user is shown them and as the shell word a user pastes back.

Why here, in the core: the hints that tell a user what to run next ("rti-rig run --resume
FOLDER") are built in every layer (runtime, app, drivers, simulator), not only the CLI; with
``shlex.quote`` a folder whose name a stream cannot print (an ASCII or Latin-1 locale, bytes
that are not UTF-8) was said as ``'\\udce9'``-style text that names no folder when pasted back,
or crashed the stream's encoder.
"""

from __future__ import annotations

import os
import shlex
import sys


def shown_path(path: object) -> str:
    """``path`` as printed for a user to copy: as it is, or, where stdout or stderr cannot
    encode it (an ASCII or Latin-1 locale, a name whose bytes are not UTF-8), as the word a
    shell reads back as the same name (:func:`shell_word`'s ``$'...'``).

    Why: the streams print a character they cannot hold as ``?`` (stdout) or ``\\xe9``
    (stderr), fine for an arrow, not for a name: ``--out é`` was said as ``→ ?``, and neither
    ``?`` (a glob) nor ``\\xe9`` pasted into a shell names the folder."""
    text = str(path)
    return text if _printable_as_is(text) else _ansi_c_quoted(os.fsencode(text))


def shell_word(path: object) -> str:
    """``path`` as one shell word naming it, for a command the user is told to run: quoted
    where it holds a space or a shell's special character (``shlex.quote``), and as ``$'...'``
    (bash, zsh, ksh, BusyBox and POSIX.1-2024 sh) where it holds a control character or stdout
    or stderr cannot print it, each byte of the name outside printable ASCII written
    ``\\xHH``: the bytes the file system holds, whatever the terminal's encoding, so the word
    pasted back names the same folder.

    Only for text shown to a user: a real subprocess gets its arguments as a list, unquoted."""
    text = str(path)
    if _printable_as_is(text):
        return shlex.quote(text)
    return _ansi_c_quoted(os.fsencode(text))


def _printable_as_is(text: str) -> bool:
    """Whether ``text`` can be shown as it is: every character printable (no control
    character, DEL, C1 code or invisible format character) and held by both standard
    streams' encodings.

    Why printable too: a tab or newline in a name pasted back is not the name (the shell
    splits the word or the line), ``\x01`` shows as nothing or ``^A``, and an escape
    sequence in a file name printed raw is executed by the terminal (recolouring, moving
    the cursor, retitling the window) instead of being shown; ``$'...'`` says each such
    byte as ``\\xHH``, which the shell reads back as the bytes on disk."""
    if not text.isprintable():
        return False
    for stream in (sys.stdout, sys.stderr):
        try:
            text.encode(getattr(stream, "encoding", None) or "utf-8")
        except (UnicodeEncodeError, LookupError):
            return False
    return True


def _ansi_c_quoted(name: bytes) -> str:
    """``name``'s bytes as a shell's ANSI-C quoted word: printable ASCII as itself (``'`` and
    ``\\`` escaped), any other byte as two hex digits."""
    chars = []
    for byte in name:
        if byte in b"'\\":
            chars.append("\\" + chr(byte))
        elif 0x20 <= byte < 0x7F:
            chars.append(chr(byte))
        else:
            chars.append(f"\\x{byte:02x}")
    return "$'" + "".join(chars) + "'"


def pip_install(*requirements: str, upgrade: bool = False) -> str:
    """The command that installs ``requirements`` into the environment running rti-rig: its
    own interpreter's pip (``/path/.venv/bin/python -m pip install ...``), as shell words.

    Why: the hints said a bare ``pip install gphoto2``. The README installs rti-rig into
    ``.venv`` and runs ``.venv/bin/rti-rig`` without activating it, so the ``pip`` a shell
    finds is another environment's (or the system's, which Debian and Ubuntu refuse as
    "externally managed"): the package went elsewhere and rti-rig still said it was missing."""
    words = [shell_word(sys.executable), "-m", "pip", "install"]
    words += ["-U"] if upgrade else []
    return " ".join(words + [shlex.quote(r) for r in requirements])


def pip_upgrade(requirement: str) -> str:
    """:func:`pip_install` of ``requirement`` with ``-U``: the command that updates it."""
    return pip_install(requirement, upgrade=True)
