"""How `rti-rig fit` keeps the C heap from holding memory it has freed (glibc's malloc).

A fit's phases each need a few tens of MB for a moment — decoding JPEGs (two threads, 15 MB
each at 2.5 MP), the pixel sample (22 MB at 72 images), the bands (8 MB each, plus the fit's
temporaries), the 16-bit PNG buffers — and free them before the next. Measured at 72 images ×
2.5 MP (issue #29's acquisition), glibc kept most of that freed memory resident, for two
reasons:

* **One heap per thread.** glibc gives each thread that allocates its own arena (decode
  threads, band readers, the prefetch thread); memory freed in one arena is not reused by the
  others, so each phase stacked its peak on top of the last one's leftovers (anonymous memory
  134 MB where the live arrays never exceeded 30 MB). :func:`use_one_heap` caps glibc at one
  arena for the process (``mallopt(M_ARENA_MAX, 1)``): the threads of a fit allocate a few
  large arrays each per band, so sharing one heap's lock costs nothing measurable.
* **Freed memory kept for reuse.** Even in one heap, freed chunks below the top stay resident
  until the heap is trimmed. :func:`release_free_memory` (``malloc_trim(0)``) returns them to
  the system; the fit calls it between phases, a few times per fit (each call is a walk of the
  heap, well under a millisecond here).

Both are no-ops where the C library is not glibc (macOS, Windows, musl): there the figures
are whatever that allocator does, and the outputs are the same either way (allocation never
changes a computed value).
"""

from __future__ import annotations

import ctypes
from functools import cache
from typing import Any

#: glibc's ``mallopt`` parameter number for the arena limit (malloc.h: ``M_ARENA_MAX -8``).
M_ARENA_MAX = -8


@cache
def _glibc() -> Any | None:
    """The process's C library when it is glibc (has ``malloc_trim`` and ``mallopt``)."""
    try:
        libc = ctypes.CDLL(None)  # the C library already loaded (no ldconfig subprocess)
    except (OSError, TypeError):  # Windows has no "the process itself" to open
        return None
    if not (hasattr(libc, "malloc_trim") and hasattr(libc, "mallopt")):
        return None
    return libc


def use_one_heap() -> bool:
    """Cap glibc at one malloc arena for this process (threads created afterwards share it).
    True when the cap was set. It stays set for the life of the process, so `rti-rig fit`
    calls it (one command per process), not :func:`rti_rig.app.usecases.fit.run_fit`, which
    Dask workers and test processes run among other work."""
    libc = _glibc()
    return bool(libc is not None and libc.mallopt(M_ARENA_MAX, 1) == 1)


def release_free_memory() -> bool:
    """Return freed heap memory to the system; True when glibc released some."""
    libc = _glibc()
    return bool(libc is not None and libc.malloc_trim(0) == 1)
