"""Make a session's writes fail as a full, read-only or failing disk would, at a chosen file.

Every file a session writes is made durable with ``os.fsync`` before it counts (image
temporaries, journal lines, ``lights.lp`` and the manifest's temporaries), so failing the
``fsync`` of the n-th write to a chosen kind of file reproduces the moment a real disk fills up
there, with the same ``OSError`` (``ENOSPC``, ``EROFS``, ``EIO``) and the partial file it leaves
— no real full disk needed. Used by the tests and the fault campaign::

    with failing_writes("journal", after=3, errno_code=errno.ENOSPC):
        ...  # the 4th journal append fails
"""

from __future__ import annotations

import contextlib
import errno
import os
from collections.abc import Iterator
from typing import Any

#: Where a session writes, by the name of the file being made durable.
WRITE_POINTS: dict[str, tuple[str, ...]] = {
    "tiff": (".tif.partial",),
    "jpeg": (".jpg.partial",),
    "journal": ("journal.jsonl",),
    "lp": (".lights.lp.tmp",),
    "manifest": (".manifest.json.tmp",),
}

ERRNOS = {"ENOSPC": errno.ENOSPC, "EROFS": errno.EROFS, "EIO": errno.EIO}


class _FailingOs:
    """The ``os`` module, except that ``fsync`` fails past the n-th write to matching files."""

    def __init__(self, real: Any, suffixes: tuple[str, ...], after: int, code: int) -> None:
        self._real, self._suffixes, self._after, self._code = real, suffixes, after, code
        self.seen = 0
        self.failed = 0

    def __getattr__(self, name: str) -> Any:
        return getattr(self._real, name)

    def fsync(self, fd: int) -> None:
        try:
            path = self._real.readlink(f"/proc/self/fd/{fd}")
        except OSError:
            path = ""
        if path.endswith(self._suffixes):
            self.seen += 1
            if self.seen > self._after:
                self.failed += 1
                raise OSError(self._code, os.strerror(self._code), path)
        self._real.fsync(fd)


@contextlib.contextmanager
def failing_writes(point: str, after: int, errno_code: int = errno.ENOSPC) -> Iterator[_FailingOs]:
    """Within the block, every write to ``point`` (see :data:`WRITE_POINTS`) after the first
    ``after`` ones fails with ``errno_code``, as a disk that has filled up stays full."""
    import rti_rig.core.image_files as image_files
    import rti_rig.runtime.session as session

    if point not in WRITE_POINTS:
        raise ValueError(f"unknown write point {point!r}; choose from {', '.join(WRITE_POINTS)}")
    fake = _FailingOs(os, WRITE_POINTS[point], after, errno_code)
    saved = image_files.os, session.os
    image_files.os = fake  # type: ignore[assignment]
    session.os = fake  # type: ignore[assignment]
    try:
        yield fake
    finally:
        image_files.os, session.os = saved  # type: ignore[assignment]
