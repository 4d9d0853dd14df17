"""How a run that never recorded its end most likely ended, for the messages that say it.

A run records its end in ``manifest.json`` (``runner.finish_reason``). Killed outright (kill
-9, a power cut) it cannot; nor where the disk filled so far that the manifest's new copy
could not be written: the manifest then still says ``running`` and ``null``, as during a
capture. ``fit``'s verdict and a refused resume had called every such run "killed" (or "a
power cut?"), which sent a user whose disk had filled looking for a crash. The journal names
the last image the run committed; if the session's disk has less room now than that image
took, the full disk is named as the likely cause; otherwise all three causes are.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import Any

#: the causes a run's missing end can have, as messages list them
CAUSES = "killed, a power cut, or a disk too full to record its end"

#: the ``finish_reason`` a resume records in ``runs`` for an earlier run that recorded no end:
#: which of :data:`CAUSES` it was is not known (it had been recorded as ``"crashed"``)
UNRECORDED = "unrecorded"


def last_image_bytes(root: Path, journal: Sequence[dict[str, Any]] | None = None) -> int | None:
    """The bytes on disk of the last image the journal of ``root`` lists (its JPEG and linear
    TIFF), None where the journal or the files cannot tell (junk, missing, unreadable).

    ``journal``: its records as the caller already read them (``scan_journal``'s, a step
    proven by its record file where its line was never written among them, last), so that it
    is not read again; None: read here, line by line, tolerating junk."""
    if journal is None:
        journal = _journal_lines(root)
        if journal is None:
            return None
    for entry in reversed(journal):
        if not isinstance(entry, dict) or not isinstance(entry.get("image"), str):
            continue
        names = [entry["image"]]
        if isinstance(entry.get("linear_image"), str):
            names.append(entry["linear_image"])
        try:
            return sum((root / name).stat().st_size for name in names)
        except OSError:
            return None
    return None


def _journal_lines(root: Path) -> list[dict[str, Any]] | None:
    """The journal's lines that are JSON objects, in order (None: it cannot be read)."""
    try:
        lines = (root / "journal.jsonl").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    entries = []
    for line in lines.splitlines():
        try:
            entry = json.loads(line)
        except ValueError:
            continue
        if isinstance(entry, dict):
            entries.append(entry)
    return entries


def full_disk_now(root: Path, journal: Sequence[dict[str, Any]] | None = None) -> str | None:
    """``"its disk has … free, less than its last image took (…)"`` where the disk of ``root``
    could not hold another image like the journal's last one; None where it could, or where
    either cannot be known (``journal``: as for :func:`last_image_bytes`)."""
    size = last_image_bytes(root, journal)
    try:
        free = shutil.disk_usage(root).free
    except OSError:
        return None
    if size is None or free >= size:
        return None
    return f"its disk has {_mb(free)} free, less than its last image took ({_mb(size)})"


def unrecorded_end(root: Path, journal: Sequence[dict[str, Any]] | None = None) -> str:
    """``root``'s last run ended without recording how: the words for it, naming a full disk
    as the likely cause where :func:`full_disk_now` finds one (``journal``: the journal's
    records where the caller has read them, as for :func:`last_image_bytes`)."""
    full = full_disk_now(root, journal)
    if full is not None:
        return (
            f"it stopped without recording why, and {full}: most likely the disk filled "
            "(free space on it before continuing)"
        )
    return f"it stopped without recording why ({CAUSES})"


def _mb(n: int) -> str:
    return f"{n / 1e6:.1f} MB"
