"""Output folders a command will write into, checked before any work is done."""

from __future__ import annotations

from pathlib import Path

from rti_rig.core.errors import RtiRigError

#: A file written and removed to prove the folder writable (permissions, read-only mounts).
PROBE_NAME = ".rti-rig-write-test"


def ensure_writable_folder(folder: Path) -> None:
    """Create ``folder`` (and its parents) and prove it writable, or refuse by name.

    Why: a command that computes for minutes (a fit, a benchmark) must not find out at the end
    that it cannot write its results; an ``OSError`` there reached users as a traceback.

    A file at ``folder`` (or at a folder above it) is refused as such, as ``export-lp`` names
    a file given for a folder: ``mkdir`` had been told "cannot write there (File exists: …);
    choose a folder you can write to", which reads as a permission problem.
    """
    existing = next((p for p in (folder, *folder.parents) if p.exists()), None)
    if existing is not None and not existing.is_dir():
        what = " is a file" if existing == folder else f": {existing} is a file, not a folder"
        raise RtiRigError(f"--out {folder}{what}: give a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / PROBE_NAME
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        where = f": {exc.filename}" if exc.filename else ""
        raise RtiRigError(
            f"--out {folder}: cannot write there ({exc.strerror or exc}{where}); choose a "
            "folder you can write to"
        ) from None
