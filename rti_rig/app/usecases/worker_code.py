"""Whether a Dask cluster's workers run the same rti-rig as this machine.

Why: the tasks of ``rti-rig fit --scheduler`` name rti-rig's functions and classes by module
(``rti_rig.app.usecases.fit_batch.fit_one``, its ``BatchItem`` result), so a worker with
another rti-rig installed either cannot read a task or sends back a result this machine
cannot read. A batch on such a cluster printed Dask's raw "Failed to deserialize" traceback
and called a session "failed: ModuleNotFoundError" whose fit stood complete in ``--out``. The
code is compared before any task is sent.

The function run on the workers is built by :func:`_identity_function` as a nested function,
which ``cloudpickle`` sends by value: a worker reads it with the standard library alone,
whatever rti-rig it has (or none), and it imports that worker's own ``rti_rig``. It answers
with a plain dict (a class of this module would need this module on the worker), turned into
a :class:`WorkerCode` here.

The fingerprint covers every package rti-rig installs, not only the ``rti_rig/`` folder:
``rti_rig.drivers``, ``.planner``, ``.simulator`` and ``.rig_configs`` come from top-level
folders of the checkout (pyproject's package-dir mapping), so in an editable install they are
not under ``rti_rig/`` at all, and in a wheel they are. Each package's files are keyed by the
package's dotted name and their path inside it, so the same code gives the same fingerprint
wherever and however it is laid out.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, NamedTuple

#: The packages rti-rig installs whose folders are not inside ``rti_rig/`` in a checkout
#: (pyproject's ``[tool.setuptools.package-dir]``; a test holds the two equal). An editable
#: install's finder maps them, so they cannot be found by listing ``rti_rig``'s folder.
MAPPED_PACKAGES: tuple[str, ...] = (
    "rti_rig.drivers",
    "rti_rig.planner",
    "rti_rig.simulator",
    "rti_rig.rig_configs",
)

#: The libraries whose versions a worker must share with this machine, and how much of the
#: version must agree: ``"exact"``, or ``"major"`` (the number before the first dot).
#:
#: Why these: ``distributed`` and ``dask`` exchange the scheduler's and the workers' messages
#: and the task graph, whose forms change between releases (a worker of distributed 2025.1.0
#: under a 2026.8.0 client died on its first task, ``TypeError: ComputeTaskEvent…``, and the
#: fit said after 80 s only that the checked workers "have all left"); ``cloudpickle`` writes
#: the fit's functions and this module's check classes by value on this machine and reads them
#: on the worker (Dask lists all three as required to match). ``numpy`` carries the bands'
#: results: arrays pickled by numpy 2 name ``numpy._core``, which numpy 1 cannot import, while
#: within one major version array pickles are read both ways, so only the major must agree
#: (an exact pin would refuse clusters that work). Not compared: Dask's transport libraries
#: (tornado, msgpack), which distributed's own requirements keep working together.
STACK_PACKAGES: tuple[tuple[str, str], ...] = (
    ("distributed", "exact"),
    ("dask", "exact"),
    ("cloudpickle", "exact"),
    ("numpy", "major"),
)

#: The Python a worker must share with this machine, to its minor version (``3.11``): reported
#: in a worker's ``stack`` under this name beside :data:`STACK_PACKAGES`.
#:
#: Why: cloudpickle sends the fit's functions and this module's check classes by value, as the
#: byte code of this machine's Python, which another minor version does not run (3.11's under
#: 3.12 fails, or crashes the worker, in errors that name no version); within one minor the
#: byte code is the same. It is asked first of Dask itself (:func:`worker_pythons`), which
#: needs no pickled function on the worker.
PYTHON = "python"

#: The files a wheel ships (code and the rig configs' package data): stray files of a
#: checkout (editor backups, caches) would otherwise tell an editable install from a wheel.
FINGERPRINTED_SUFFIXES: tuple[str, ...] = (".py", ".toml", ".lp")


@dataclass(frozen=True)
class WorkerCode:
    """Which rti-rig a process runs: its ``__version__`` (``None`` when it declares none), the
    fingerprint of its installed files, or the ``problem`` that kept rti-rig from importing
    there (then neither of the others is known)."""

    version: str | None
    fingerprint: str | None
    problem: str | None = None
    #: the :data:`STACK_PACKAGES` versions found there, as ``(name, version)`` pairs ("" for
    #: a library that is not there); empty when not reported (see :func:`stack_differences`)
    stack: tuple[tuple[str, str], ...] = ()

    def same_code(self, other: WorkerCode) -> bool:
        """Whether ``other`` runs this rti-rig (its libraries' versions aside)."""
        mine = (self.version, self.fingerprint, self.problem)
        return mine == (other.version, other.fingerprint, other.problem)


@dataclass(frozen=True)
class Unasked:
    """A worker whose check failed there (an error returned in its answer's place): which
    rti-rig it runs is not known, so it is not called another one."""

    reason: str


def _identity_function(
    mapped: tuple[str, ...] = MAPPED_PACKAGES,
    suffixes: tuple[str, ...] = FINGERPRINTED_SUFFIXES,
    compared: tuple[tuple[str, str], ...] = STACK_PACKAGES,
) -> Callable[[], dict[str, Any]]:
    """The function that reports, as a plain dict of :class:`WorkerCode`'s fields, the rti-rig
    of the process it runs in and the versions of the libraries its tasks need (``stack``, a
    dict, reported whatever became of rti-rig's import). Nested, so that it is pickled by
    value (see the module's note); it refers to no global of this module (``mapped``,
    ``suffixes`` and ``compared`` travel with it)."""

    def rti_rig_identity() -> dict[str, Any]:
        stack = library_versions()
        found = code_identity()
        return {**found, "stack": stack}

    def library_versions() -> dict[str, str]:
        """The version of each compared library in this process, as it must agree: the
        imported module's ``__version__`` (the code that runs, not the installed metadata),
        cut to its major where only that must agree; "" where it cannot be imported."""
        import importlib
        import sys

        versions: dict[str, str] = {"python": f"{sys.version_info[0]}.{sys.version_info[1]}"}
        for name, agree in compared:
            try:
                version = str(getattr(importlib.import_module(name), "__version__", ""))
            except Exception:  # not installed there (or broken): told as missing
                version = ""
            if agree == "major" and version:
                version = version.split(".")[0] + ".x"
            versions[name] = version
        return versions

    def code_identity() -> dict[str, str | None]:
        import hashlib
        import importlib.util
        import sys
        from pathlib import Path

        already = "rti_rig" in sys.modules  # imported before this check, from files then
        try:
            import rti_rig
        except Exception as exc:  # a worker without rti-rig says so
            return {"version": None, "fingerprint": None, "problem": f"{type(exc).__name__}: {exc}"}
        roots = ("rti_rig", *mapped)
        folders: dict[str, Path | None] = {}
        for name in roots:
            spec = importlib.util.find_spec(name)
            places = list(spec.submodule_search_locations or []) if spec else []
            folders[name] = Path(places[0]).resolve() if places else None
        # In a wheel the mapped packages sit inside rti_rig/: each is hashed under its own name.
        nested = {folder for name, folder in folders.items() if name != "rti_rig" and folder}
        digest = hashlib.sha256()
        code: dict[str, str] = {}  # the .py files alone, by path: what a process imports
        everything: list[tuple[str, Path]] = []
        vanished: list[str] = []  # listed, then gone before they were read
        for name in roots:
            folder = folders[name]
            digest.update(f"package {name}\0".encode())
            if folder is None:
                digest.update(b"missing\0")
                continue
            files = []
            where = name.replace(".", "/")
            try:
                for path in folder.rglob("*"):
                    if (
                        path.is_file()
                        and path.suffix in suffixes
                        and "__pycache__" not in path.parts
                        and not any(parent in nested for parent in path.parents if parent != folder)
                    ):
                        files.append((path.relative_to(folder).as_posix(), path))
            except FileNotFoundError as exc:  # a folder listed, then gone before its own listing
                gone_folder = Path(str(exc.filename or folder))
                inside = gone_folder.relative_to(folder) if folder in gone_folder.parents else None
                vanished.append(f"{where}/{inside.as_posix()}/" if inside else f"{where}/")
                continue
            for relative, path in sorted(files):
                try:
                    content = path.read_bytes()
                except FileNotFoundError:  # deleted or moved since it was listed
                    vanished.append(f"{where}/{relative}")
                    continue
                digest.update(relative.encode() + b"\0" + content + b"\0")
                if path.suffix == ".py":
                    code[f"{where}/{relative}"] = hashlib.sha256(content).hexdigest()
                    everything.append((f"{where}/{relative}", path))
        fingerprint = digest.hexdigest()[:12]
        version = getattr(rti_rig, "__version__", None)
        said = None if version is None else str(version)
        if vanished:  # an incomplete listing is no fingerprint, nor kept as the first check's
            return {"version": said, "fingerprint": None, "problem": gone(vanished)}
        # The code this process runs is what it imported, not what its .py files say now (the
        # .toml and .lp are read when used). The .py files' contents at this process's first
        # check are kept in it, with what that check found; every later check compares
        # contents with them, not dates (a file saved again unchanged is the same code; one
        # edited with its date kept is not).
        first = vars(rti_rig).get("_rti_rig_first_check")
        if first is None:
            first = vars(rti_rig).setdefault(
                "_rti_rig_first_check",
                (fingerprint, code, None if not already else imported_problem(rti_rig, everything)),
            )
        first_fingerprint, first_code, first_problem = first
        changed = sorted(
            relative
            for relative in set(code) | set(first_code)
            if code.get(relative) != first_code.get(relative)
        )
        if changed:
            named = ", ".join(changed[:3]) + (" …" if len(changed) > 3 else "")
            problem: str | None = (
                f"its rti-rig source changed after this process imported it ({named}): it runs "
                "the code it imported, not the files there now; restart it"
            )
        else:
            problem = first_problem
        if problem is not None:
            return {"version": said, "fingerprint": first_fingerprint, "problem": problem}
        return {"version": said, "fingerprint": fingerprint, "problem": None}

    def imported_problem(rti_rig: Any, everything: list[tuple[str, Any]]) -> str | None:
        """Why the files of a process that imported rti-rig before its first check may not be
        the code it imported (by their dates against the time of the import), or ``None``.
        Only then are dates asked: a first check that imports rti-rig itself reads the very
        files it imports."""
        import time

        imported_at = getattr(rti_rig, "IMPORTED_AT_NS", None)
        if not isinstance(imported_at, int):
            # Imported by an rti-rig that kept no import time (one older than IMPORTED_AT_NS,
            # e.g. for an earlier fit's tasks): its files may have been replaced since by any
            # others, their dates kept (a pull, `cp -a`).
            return (
                "it imported rti-rig before this check, from an rti-rig that kept no record of "
                "when: it may run other code than the files there now; restart it"
            )
        now = time.time_ns()
        changed: list[str] = []
        ahead: list[str] = []  # dated after this clock: when they changed is not known
        vanished: list[str] = []
        for relative, path in sorted(everything):
            try:
                modified = path.stat().st_mtime_ns
            except FileNotFoundError:  # read a moment ago, deleted or moved since
                vanished.append(relative)
                continue
            if modified > now:
                ahead.append(str(path))
            elif modified > imported_at:
                changed.append(relative)
        if vanished:
            return gone(vanished)
        if changed:
            named = ", ".join(changed[:3]) + (" …" if len(changed) > 3 else "")
            return (
                f"its rti-rig source changed after this process imported it ({named}): it runs "
                "the code it imported, not the files there now; restart it"
            )
        if ahead:
            # Not "changed after the import": a date to come says nothing of when (a file
            # server's clock ahead, a copy that kept a future date), and a restart alone would
            # be refused the same way until the clock passed it.
            named = ", ".join(ahead[:3]) + (" …" if len(ahead) > 3 else "")
            return (
                f"its rti-rig source file(s) {named} are dated after this computer's clock, so "
                "whether they changed since this process imported rti-rig cannot be told: give "
                "them the present date (`touch FILE`; set the clocks right if a file server's "
                "runs ahead), then restart it"
            )
        return None

    def gone(vanished: list[str]) -> str:
        """Why the code of a process one of whose rti-rig ``.py`` files vanished while it was
        checked (listed, then deleted or moved before it was read) cannot be told.

        Why: the check had failed there with a bare ``FileNotFoundError``, said as a worker
        that "could not be asked" (check that it is running and reachable), or a check that
        failed: its rti-rig is being changed under it (a ``git checkout``, a reinstall), and
        what it runs is the code it imported, which no file there shows any more."""
        named = ", ".join(vanished[:3]) + (" …" if len(vanished) > 3 else "")
        # a folder (named with its final /) can vanish as a whole: a subpackage a checkout drops
        noun = "file" if not any(v.endswith("/") for v in vanished) else "file or folder"
        return (
            f"its rti-rig source {noun} {named} vanished while it was being checked (deleted or "
            "moved after its folder was listed): its rti-rig is being changed, so the code it "
            "runs cannot be told; restart it once the change is done"
        )

    return rti_rig_identity


def _as_worker_code(answer: Mapping[str, Any]) -> WorkerCode:
    """A worker's plain answer as the typed value (missing fields read as unknown)."""

    def field(key: str) -> str | None:
        value = answer.get(key)
        return None if value is None else str(value)

    told = answer.get("stack")
    stack = tuple((str(k), str(v)) for k, v in told.items()) if isinstance(told, Mapping) else ()
    return WorkerCode(field("version"), field("fingerprint"), field("problem"), stack)


def stack_differences(mine: WorkerCode, theirs: WorkerCode) -> list[tuple[str, str, str]]:
    """The compared libraries (:data:`STACK_PACKAGES`) whose version differs between ``mine``
    and ``theirs``, as ``(name, mine, theirs)``, the :data:`PYTHON` first; none when ``theirs``
    reported no versions (a check of an rti-rig from before this one: it cannot be told, and
    its code differs), and no Python when it reported none (an rti-rig from before 2026-12-01)."""
    if not theirs.stack:
        return []
    ours, found = dict(mine.stack), dict(theirs.stack)
    names = [name for name, _ in STACK_PACKAGES]
    if PYTHON in found:
        names.insert(0, PYTHON)
    return [
        (name, ours.get(name, ""), found.get(name, ""))
        for name in names
        if ours.get(name, "") != found.get(name, "")
    ]


def python_minor(version: str) -> str:
    """``3.11`` of ``3.11.7.final.0`` (Dask's form of a Python version)."""
    return ".".join(version.split(".")[:2])


def worker_pythons(client: Any) -> dict[str, str]:
    """Each worker's Python, to its minor version (``3.11``), as Dask's own version report
    gives it (``Client.get_versions``): no function of this machine runs on the worker, so a
    worker of another Python answers (the rti-rig check, pickled by value, may not run there).
    Workers that did not answer are missing; none when the report cannot be had."""
    try:
        report = client.get_versions(check=False)
        workers = report["workers"]
    except Exception:  # the scheduler lost, or an older Dask: the rti-rig check still runs
        return {}
    found: dict[str, str] = {}
    for worker, answer in workers.items():
        if not isinstance(answer, Mapping):
            continue
        packages = answer.get("packages") or {}
        host = answer.get("host") or {}
        version = packages.get(PYTHON) or host.get(PYTHON)
        if version:
            found[worker] = python_minor(str(version))
    return found


def describe_library(name: str, version: str) -> str:
    """``distributed 2026.8.0``, ``numpy 2.x``, ``Python 3.11``, or ``no numpy``."""
    if name == PYTHON:
        return f"Python {version}" if version else "no Python version"
    return f"{name} {version}" if version else f"no {name}"


@lru_cache(maxsize=1)
def local_identity() -> WorkerCode:
    """This process's rti-rig, computed once per process."""
    return _as_worker_code(_identity_function()())


def worker_identities(client: Any) -> dict[str, WorkerCode | Unasked]:
    """Each worker's rti-rig, computed on the worker itself (or why it could not be)."""
    answers: Mapping[str, Any] = client.run(_identity_function(), on_error="return")
    identities: dict[str, WorkerCode | Unasked] = {}
    for worker, answer in answers.items():
        if isinstance(answer, Mapping):
            identities[worker] = _as_worker_code(answer)
        else:  # the function failed there: an exception returned in its place
            identities[worker] = Unasked(f"{type(answer).__name__}: {answer}")
    return identities


def describe(code: WorkerCode) -> str:
    """``rti-rig 0.1.0, code 1a2b3c4d5e6f`` (or what kept it from being known, or why the
    code it runs is not what its files say)."""
    if code.problem is not None and code.version is None and code.fingerprint is None:
        return f"no rti-rig ({code.problem})"
    version = "(no version)" if code.version is None else code.version
    said = f"rti-rig {version}"
    if code.fingerprint is not None:  # none when its files could not all be read
        said += f", code {code.fingerprint}"
    return said if code.problem is None else f"{said}, but {code.problem}"


#: The Dask resource a worker holds once its own rti-rig was found to be this code
#: (:func:`tagging_plugin`), followed by the code's fingerprint; every task of a fit needs one
#: unit of it. The amount held is large so that it limits nothing but who may run the task.
TAG_PREFIX = "rti-rig-code-"
TAG_AMOUNT = 1_000_000.0


def tag_for(code: WorkerCode) -> str:
    """The resource name of ``code`` (its fingerprint): tasks asking for it run only on a
    worker process whose own rti-rig was checked to be this code."""
    return f"{TAG_PREFIX}{code.fingerprint}"


#: What a worker's :func:`tagging_plugin` found there (its ``outcome``, ``(kind, words)``), read
#: back by the client to say why a worker still in the cluster holds no tag: the kinds.
TAGGED = "tagged"
#: ... the worker runs other code (then it is refused, not failed) ...
OTHER_CODE = "other-code"
#: ... or the check itself failed there (see that worker's log).
CHECK_FAILED = "failed"


class Untagged(NamedTuple):
    """Why a worker still in the cluster holds no tag, as :func:`plugin_outcomes` read it.

    Why a kind beside the words: the fit tells a worker refused for its code from one whose
    check failed (restart it) by ``other_code``; it had told them apart by the words' first
    characters, so rewording the sentence would have changed the verdict."""

    other_code: bool
    reason: str


def tagging_plugin(code: WorkerCode) -> Any:
    """A Dask ``WorkerPlugin`` that, on every worker it is set up on — those there when it is
    registered and every one that joins or restarts later, before that worker takes any task —
    computes that worker's own rti-rig and, only if it is ``code`` (with the same
    :data:`STACK_PACKAGES` versions: a worker joining later with another distributed would die
    on its first task), gives the worker the
    resource :func:`tag_for` names (and takes it back from a worker holding it whose code is
    no longer ``code``: its source changed since it was tagged).

    Why: tasks had been kept to the checked workers by address. A worker restarted by its
    nanny (after a memory kill) comes back on another address, and the fit stopped although
    the same code was there; a worker restarted on the same fixed port with other code was
    taken for the checked one and fitted with that code. The resource belongs to the worker
    process that was checked, wherever it listens. The class is made here, nested, so that
    ``cloudpickle`` sends it by value (as :func:`_identity_function`): a worker with another
    rti-rig, or none, still reads it, and is simply not tagged.

    What it found is kept on the worker, in the plugin's ``outcome``: :data:`TAGGED`, the other
    code found there, or the error that kept the tag from being given (read by
    :func:`plugin_outcomes`), so that a worker left untagged is named with its reason.

    Why the pause and resume: Dask's scheduler reconsiders a task no worker may run
    (``no-worker``) when a worker joins or goes from paused to running, not when a worker gains
    a resource. A worker that joins (a nanny's restart mid-fit) is set up *after* it joined,
    so tasks already waiting for a tagged worker would wait for ever. A worker newly tagged
    while ``running`` is therefore set ``paused`` then ``running`` again, in one step of its
    event loop (nothing runs between the two: no task is held back, the memory monitor cannot
    interleave); the scheduler logs the two status changes as a ``worker-status-change``
    event. A worker that is not ``running`` (paused for memory, or by a user's
    ``client.run``; closing) is left as it is: it is tagged, and Dask gives it the waiting
    tasks when it resumes by itself — the tag never resumes a paused worker."""
    from distributed import WorkerPlugin

    expected = {
        "version": code.version,
        "fingerprint": code.fingerprint,
        "problem": None,
        "stack": dict(code.stack),  # a worker of other library versions is not tagged either
    }
    resource = tag_for(code)
    identity = _identity_function()
    # the kinds as closure values, sent with the class: never looked up in the worker's module
    tagged, other_code, check_failed = TAGGED, OTHER_CODE, CHECK_FAILED

    class RtiRigCodeTag(WorkerPlugin):  # type: ignore[misc]  # untyped base
        """Tags a worker running this rti-rig (see :func:`tagging_plugin`)."""

        def __init__(self) -> None:
            self.identity = identity
            self.expected = expected
            self.resource = resource
            self.amount = TAG_AMOUNT
            self.outcome: tuple[str, str] | None = None  # (kind, words): plain, as pickled

        async def setup(self, worker: Any) -> None:
            """Never raises: a worker whose check fails is left untagged, given no task (an
            error here had failed the registration, and with it the fit, for every worker);
            what happened is kept in ``outcome``."""
            from distributed.core import Status

            try:
                held = worker.state.total_resources.get(self.resource, 0)
                found = self.identity()
                if found != self.expected:  # other code (or none, or changed): no task
                    if held:  # tagged earlier (this code then): taken back
                        await worker.set_resources(**{self.resource: 0})
                    said = f"rti-rig {found.get('version')}"
                    if found.get("fingerprint") is not None:
                        said += f", code {found['fingerprint']}"
                    if found.get("problem"):
                        said += f" ({found['problem']})"
                    stack = found.get("stack") or {}
                    other = [
                        f"{name} {stack.get(name) or '(none)'} (this fit's {version or 'none'})"
                        for name, version in self.expected["stack"].items()
                        if stack.get(name) != version
                    ]
                    if other:
                        said += f", with {', '.join(other)}"
                    self.outcome = (other_code, f"it runs other code than this fit: {said}")
                    return
                if held != self.amount:
                    await worker.set_resources(**{self.resource: self.amount})
                    if worker.status == Status.running:  # see tagging_plugin: wakes tasks
                        worker.status = Status.paused
                        worker.status = Status.running
                self.outcome = (tagged, "tagged")
            except Exception as exc:  # e.g. its scheduler lost meanwhile: untagged
                self.outcome = (check_failed, f"{type(exc).__name__}: {exc}")

    return RtiRigCodeTag()


def plugin_outcomes(client: Any, name: str, workers: list[str]) -> dict[str, Untagged]:
    """What the plugin registered as ``name`` found on each of ``workers`` (its ``outcome``:
    tagged, other code, or why the check failed), or why that could not be asked (a failure,
    not other code)."""

    failed = CHECK_FAILED  # a closure value, sent with the function

    def outcome(dask_worker: Any) -> tuple[str, str]:
        plugin = dask_worker.plugins.get(name)
        if plugin is None:
            return (failed, "the rti-rig check was never set up there")
        found = getattr(plugin, "outcome", None)
        return found or (failed, "the rti-rig check has not finished there")

    answers = client.run(outcome, workers=workers, on_error="return")
    return {w: _untagged(a) for w, a in answers.items()}


def _untagged(answer: Any) -> Untagged:
    """One worker's answer to :func:`plugin_outcomes` (a ``(kind, words)`` pair, else the
    error ``client.run`` returned in its place)."""
    if isinstance(answer, tuple) and len(answer) == 2 and all(isinstance(a, str) for a in answer):
        return Untagged(answer[0] == OTHER_CODE, answer[1])
    return Untagged(False, f"it could not be asked ({type(answer).__name__}: {answer})")
