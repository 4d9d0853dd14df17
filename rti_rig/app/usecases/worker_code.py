"""Whether a Dask cluster's workers run the same rti-rig as this machine.

Why: the tasks of ``rti-rig fit --scheduler`` name rti-rig's functions and classes by module
(``rti_rig.app.usecases.fit_batch.fit_one``, its ``BatchItem`` result), so a worker with
another rti-rig installed either cannot read a task or sends back a result this machine
cannot read. A batch on such a cluster printed Dask's raw "Failed to deserialize" traceback
and called a session "failed: ModuleNotFoundError" whose fit stood complete in ``--out``. The
code is compared before any task is sent.

The function run on the workers is built by :func:`_identity_function` as a nested function,
which ``cloudpickle`` sends by value: a worker reads it with the standard library alone,
whatever rti-rig it has (or none), and it imports that worker's own ``rti_rig``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from functools import lru_cache
from typing import Any

#: What a worker whose identity could not be taken reports instead of a version.
UNKNOWN = "?"


def _identity_function() -> Callable[[], tuple[str, str]]:
    """The function that reports ``(rti_rig.__version__, fingerprint of its source)`` of the
    process it runs in. Nested, so that it is pickled by value (see the module's note); it
    refers to no global of this module."""

    def rti_rig_identity() -> tuple[str, str]:
        import hashlib
        from pathlib import Path

        try:
            import rti_rig
        except Exception as exc:  # a worker without rti-rig says so
            return ("not installed", f"{type(exc).__name__}: {exc}")
        root = Path(rti_rig.__file__).resolve().parent
        digest = hashlib.sha256()
        for path in sorted(root.rglob("*.py")):
            digest.update(path.relative_to(root).as_posix().encode() + b"\0")
            digest.update(path.read_bytes() + b"\0")
        return (str(getattr(rti_rig, "__version__", "?")), digest.hexdigest()[:12])

    return rti_rig_identity


@lru_cache(maxsize=1)
def local_identity() -> tuple[str, str]:
    """This process's ``(version, code fingerprint)``, computed once per process."""
    return _identity_function()()


def worker_identities(client: Any) -> dict[str, tuple[str, str]]:
    """Each worker's ``(version, code fingerprint)``, computed on the worker itself."""
    answers: Mapping[str, Any] = client.run(_identity_function(), on_error="return")
    identities = {}
    for worker, answer in answers.items():
        if isinstance(answer, tuple) and len(answer) == 2:
            identities[worker] = (str(answer[0]), str(answer[1]))
        else:  # the function failed there: an exception returned in its place
            identities[worker] = (UNKNOWN, f"{type(answer).__name__}: {answer}")
    return identities


def describe(identity: tuple[str, str]) -> str:
    """``rti-rig 0.1.0, code 1a2b3c4d5e6f`` (or what kept it from being known)."""
    version, code = identity
    if version == "not installed":
        return f"no rti-rig ({code})"
    return f"rti-rig {version}, code {code}"
