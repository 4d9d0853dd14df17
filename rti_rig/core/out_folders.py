"""Output folders a command will write into, checked before any work is done."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from rti_rig.core.errors import RtiRigError
from rti_rig.core.shell_words import shell_word, shown_path

#: How the file written and removed to prove the folder writable (permissions, read-only
#: mounts) is named: this, then a part unique to each probe (:func:`tempfile.mkstemp`).
PROBE_PREFIX = ".rti-rig-write-test-"


def _cannot_write_there(folder: Path, exc: OSError, option: str = "--out") -> RtiRigError:
    """The refusal of an output (``option folder``, or ``option file`` in a folder) the system
    would not let us look into or write to, naming it and the system's reason (one wording for a
    ``stat``, a ``mkdir`` and a probe file that fail)."""
    where = f": {exc.filename}" if exc.filename else ""
    return RtiRigError(
        f"{option} {shown_path(folder)}: cannot write there ({exc.strerror or exc}{where}); choose "
        "a folder you can write to"
    )


def _probe_refused(shown: Path, option: str, what: str) -> RtiRigError:
    """The refusal of ``option shown`` whose folder would not take the probe file, saying
    ``what`` the system refused and why. Why its own wording: the probe's ``OSError`` names the
    folder as its file, so ``--figure /proc/f.png`` read "cannot write there (No such file or
    directory: /proc)", as if /proc were missing, when it was the new file in it that was
    refused."""
    return RtiRigError(
        f"{option} {shown_path(shown)}: cannot write there ({what}); choose a folder you can write "
        "to"
    )


def _probe(folder: Path, shown: Path, option: str) -> None:
    """Create and remove a file of a name no other file has in ``folder``, or refuse
    ``option shown`` naming ``folder`` (not the probe's random name)."""
    try:
        handle, probe = tempfile.mkstemp(prefix=PROBE_PREFIX, dir=folder)
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise _probe_refused(
            shown, option, f"the system refused a new file in {shown_path(folder)}: {reason}"
        ) from None
    os.close(handle)
    try:
        os.unlink(probe)
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise _probe_refused(
            shown,
            option,
            f"the system refused to remove the test file {shown_path(probe)} it let us create in "
            f"{shown_path(folder)}: {reason}; remove it yourself",
        ) from None


def ensure_file_writable(path: Path, option: str = "--out") -> None:
    """Prove a file can be created in ``path``'s folder (which exists), or refuse by name.

    Why: ``rti-rig plan --figure /proc/f.png`` (a read-only card, a folder of another user's)
    was refused only after the plan was computed and written, so the same command run again
    with a good ``--figure`` needed ``--force``; an output file is written into its folder (a
    temporary file renamed over it), so the folder is what must take a new file. The probe is
    made as :func:`ensure_writable_folder` makes it."""
    _probe(path.parent, path, option)


def refuse_a_file_in_the_way(folder: Path) -> None:
    """Refuse ``--out folder`` when ``folder`` (or a folder above it) is a file, by name.

    Why: ``mkdir`` had said "cannot write there (File exists: …); choose a folder you can
    write to" (and a batch "cannot create the batch folder (File exists)"), which reads as a
    permission problem. Shared by :func:`ensure_writable_folder` and a fit batch's own folder.

    A folder the user may not look into (``--out /root/x/y`` for another user) makes
    ``Path.exists`` raise ``PermissionError`` on Python 3.11 rather than say False: that is
    refused as "cannot write there" too, not let through as a traceback."""
    try:
        existing = next((p for p in (folder, *folder.parents) if p.exists()), None)
        is_file = existing is not None and not existing.is_dir()
    except OSError as exc:
        raise _cannot_write_there(folder, exc) from None
    if is_file:
        what = (
            " is a file"
            if existing == folder
            else f": {shown_path(existing)} is a file, not a folder"
        )
        raise RtiRigError(f"--out {shown_path(folder)}{what}: give a folder")


def ensure_writable_folder(folder: Path) -> None:
    """Create ``folder`` (and its parents) and prove it writable, or refuse by name.

    Why: a command that computes for minutes (a fit, a benchmark) must not find out at the end
    that it cannot write its results; an ``OSError`` there reached users as a traceback.

    A file at ``folder`` (or at a folder above it) is refused as such
    (:func:`refuse_a_file_in_the_way`), as ``export-lp`` names a file given for a folder.

    The probe file gets a name no other file has (created exclusively, in the folder itself):
    a fixed name had replaced, then deleted, a user's file of that name in a folder given with
    ``--force``, and two commands probing one folder at once could delete each other's probe
    and fail.
    """
    refuse_a_file_in_the_way(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _cannot_write_there(folder, exc) from None
    _probe(folder, folder, "--out")


def free_name(path: Path, *, folder: bool = False) -> Path:
    """``path``, or ``path`` with ``-2``, ``-3``… added (before a file's suffix; at the end of a
    ``folder``'s name, whose dots are its own) if that is taken: the name a hint gives for a
    file or folder the command it suggests will write.

    Why one function: ``plan`` refuses an existing ``--out`` without ``--force``, ``run`` a
    non-empty folder and ``fit`` an existing one, so a hint's ``--out DIR`` pasted as printed
    made a folder named DIR, and an existing name was refused; the CLI and the session folder
    each had their own copy of this loop.

    A path with no name of its own (``.``, ``..``, ``a/..``) is named by its absolute path:
    ``--out .`` of a non-empty folder had ended in "unexpected ValueError" here."""
    path = _named(path)
    stem, suffix = (path.name, "") if folder else (path.stem, path.suffix)
    candidate, n = path, 2
    while candidate.exists() or candidate.is_symlink():
        candidate = path.with_name(f"{stem}-{n}{suffix}")
        n += 1
    return candidate


def free_folder_beside(root: Path, tag: str) -> Path:
    """A folder that does not exist yet beside ``root``, named ``ROOT-tag`` (``-2``… added if
    taken): the ``--out`` of a command a hint about session ``root`` suggests (``fit`` refuses
    an ``--out`` inside the session, so beside it, not in it). A session given as ``.`` or
    ``..`` is named by its absolute path: it has no name to add to."""
    root = _named(root)
    return free_name(root.with_name(f"{root.name}-{tag}"), folder=True)


def file_beside(root: Path, suffix: str) -> Path:
    """A file that does not exist yet beside folder ``root``, named ``ROOT{suffix}`` (``-2``…
    added before the suffix if taken): what a hint has a command write about session ``root``
    outside it. A session given as ``.`` or ``..`` is named by its absolute path (``run
    --resume .`` from inside it had ended in a ValueError: '.' has no name to add to)."""
    root = _named(root)
    return free_name(root.with_name(f"{root.name}{suffix}"))


def _named(path: Path) -> Path:
    """``path``, or its absolute, normalised form where it has no name to add to (``.``,
    ``..``, ``a/..``, the root ``/`` excepted: it has none either way)."""
    path = Path(path)
    if path.name in ("", "..") or path.parts[-1:] == ("..",):
        return Path(os.path.normpath(path.absolute()))
    return path


def fit_beside(session: Path | str) -> str:
    """``rti-rig fit S --out S-fit``: the fit a hint names as a complete session's next step,
    its ``--out`` a free folder beside the session (:func:`free_folder_beside`), both as shell
    words.

    Why one function: ``--out FOLDER`` had been printed, which pasted made a folder named
    FOLDER; the fix then spelled this command out in eight places (run's words, fit's verdict,
    the session's refusals)."""
    root = Path(session)
    return f"rti-rig fit {shell_word(root)} --out {shell_word(free_folder_beside(root, 'fit'))}"
