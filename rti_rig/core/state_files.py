"""Small per-user state files replaced whole: the dome's duty ledger, the emulated servos' latch.

Why one writer: both keep a few hundred bytes between rti-rig commands in a state folder, and a
command killed while writing must leave the previous file whole (a torn ledger would forget hot
LEDs; a torn latch would forget a fault). A temporary file in the same folder, then
``os.replace``, gives that on POSIX and Windows. No fsync: these are not captured data, and a
power loss that loses the last write costs at most one duty window of waiting or one latched
error (the session's own files go through ``rti_rig.runtime.session``'s fsynced writers).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path


def replace_text(path: Path, body: str) -> None:
    """Replace ``path`` with ``body`` (UTF-8) in one step, making its folder (owner only) if
    needed; on any failure the temporary file is removed and the old file is left whole.
    Raises OSError for the caller to say."""
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(body)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
