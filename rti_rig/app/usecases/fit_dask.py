"""`rti-rig fit --scheduler`: the same fit, its bands (or a batch's sessions) run on Dask.

Two ways to scale out, both with outputs identical to the single-process fit:

* **One session, bands as tasks.** The acquisition becomes a lazily read ``dask.array``
  (:func:`rti_rig.reconstruct.lazy_stack.lazy_stack`: bands of rows × all lights, each read
  from the files where it is computed) and every band is fitted by the same
  :func:`rti_rig.app.usecases.fit_bands.fit_band` the single-process loop calls, on the same
  row bands. Model choice, quantisation ranges, writing the files and QA run here, in the
  process that runs ``rti-rig fit`` (they read a pixel sample and a crop, not the stack).
* **A batch, sessions as tasks** (``rti-rig fit S1 S2 … --out ROOT --scheduler ADDRESS``):
  each unfinished session is one task running :func:`rti_rig.app.usecases.fit_batch.fit_one` on a
  worker — the whole single-process fit, into a partial folder renamed when complete — so the
  batch stays resumable: finished sessions are skipped, a killed batch leaves only partial
  folders, which the next run removes and redoes.

``scheduler`` is ``"threads"`` (local threads in this process, one per core, each computing a
band's Dask graph: nothing to set up) or the address of a ``dask scheduler``
(``tcp://host:8786``). Workers must see the session
files at the same paths as this machine; every error says so. They must run the same rti-rig
too: a cluster whose workers run other code is refused before any task is sent
(:mod:`rti_rig.app.usecases.worker_code`), and tasks go only to worker processes checked to run
this code, those that join or restart later included (:class:`Cluster`).

Whether a scheduler address can be used at all (parsed, looked up, TLS, a bounded first
connection) is :mod:`rti_rig.app.usecases.scheduler_probe`'s. Dask is imported only in these
two modules, and they only when ``--scheduler`` is given.
"""

from __future__ import annotations

import logging
import os
import socket
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from contextlib import contextmanager, suppress
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from rti_rig.app.usecases.fit import (
    BandRunner,
    FitRequest,
    FitResult,
    acquisition_files,
    read_image,
    refuse_out_inside_a_session,
    run_fit,
)
from rti_rig.app.usecases.fit_bands import (
    BandFit,
    BandPlan,
    blas_threads,
    fit_band,
    fit_band_recording,
)
from rti_rig.app.usecases.fit_batch import (
    BatchItem,
    EarlierFit,
    Outcome,
    batch_out_dir,
    earlier_fit,
    fit_one,
    plan_batch,
    prepare_batch,
    with_notes,
)
from rti_rig.app.usecases.scheduler_probe import (
    SHARED_PATHS,
    THREADS,
    SchedulerError,
    checked_address,
    probe,
    unreachable_scheduler,
)
from rti_rig.app.usecases.worker_code import (
    PYTHON,
    Unasked,
    Untagged,
    WorkerCode,
    describe,
    describe_library,
    local_identity,
    plugin_outcomes,
    stack_differences,
    tag_for,
    tagging_plugin,
    worker_identities,
    worker_pythons,
)
from rti_rig.core.errors import RtiRigError
from rti_rig.core.shell_words import shown_path
from rti_rig.reconstruct.lazy_stack import ImageReadError, StackSource, lazy_stack
from rti_rig.reconstruct.stack import ImageStack

#: Seconds to wait for the scheduler to answer, then for at least one worker to join.
CONNECT_TIMEOUT_S = 20.0
WORKERS_TIMEOUT_S = 60.0
#: Bands in flight per worker thread (bounds the results waiting to be written).
BANDS_IN_FLIGHT_PER_THREAD = 2

#: The reason Dask gives the futures it cancels when the client loses the scheduler
#: (``FutureCancelledError.reason``): a lost scheduler surfaces so, not as an ``OSError``.
SCHEDULER_LOST = "scheduler-connection-lost"

#: The reason given to the future of a band (or a batch's session) whose result could not be
#: fetched from the worker that holds it, cancelled by :class:`_GatherWatch`.
GATHER_FAILED = "rti-rig-result-unreachable"
#: The reason given to the futures still to compute when no worker checked to run this rti-rig
#: has been in the cluster for :data:`CHECKED_GRACE_S` (:class:`_CheckedWatch`): the tasks may
#: run on no other worker.
CHECKED_GONE = "rti-rig-checked-workers-gone"
#: Seconds between looks, while tasks are out, at whether a checked worker is there.
CHECKED_POLL_S = 5.0
#: Seconds without any checked worker before the fit stops: a worker restarted by its nanny
#: (a memory kill) is away for the seconds its restart takes, then checked again as it joins.
CHECKED_GRACE_S = 60.0
#: Failed fetches of one result before the fit stops. Dask retries a failed fetch at once and
#: for ever, logging "Couldn't gather N keys, rescheduling" each time (hundreds a second with
#: a worker that answers the scheduler but not a fetch): one or two are a worker lost and its
#: work done again elsewhere, more a worker whose results cannot be reached.
GATHER_TRIES = 5
#: ... and the least time (seconds) since that result's first failed fetch. Tries alone end
#: too soon: a refused or reset fetch fails 5 times in about half a second, so a network
#: blip of under a second, which Dask rides through, had ended the fit.
GATHER_PATIENCE_S = 60.0


class _GatherWatch(logging.Filter):
    """Keeps Dask's "Couldn't gather … rescheduling" warnings from the user, and stops a fetch
    that keeps failing.

    Why: a result the client could not fetch (its worker lost, or a worker the scheduler
    cannot connect to: a firewall, an address only its own host can reach) is retried by Dask
    at once and without end, each try a WARNING line on this command's stderr. A worker lost
    once is Dask's own recovery (the band is computed again, the outputs the same): a normal
    run's stderr got that noise. A result that can never be fetched held the fit for ever,
    stderr flooding. After :data:`GATHER_TRIES` failures of one result, the last at least
    :data:`GATHER_PATIENCE_S` after its first, its future is cancelled with the reason
    :data:`GATHER_FAILED`, which the waiting code says by name. A fetch of a result it does
    not watch (another fit's in this process) is let through, not hidden: the other fit's
    watch, which sees a record only if this one lets it pass, counts it."""

    def __init__(self, client: Any, clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__()
        self.client = client
        #: what :data:`GATHER_PATIENCE_S` is measured by (a test gives a scripted one)
        self.clock = clock
        self.failures: dict[Any, int] = {}
        self.first_failed: dict[Any, float] = {}
        self.cancelled: set[Any] = set()
        self.futures: dict[Any, Any] = {}

    def track(self, future: Any) -> Any:
        """Watch ``future``'s fetches (returns it)."""
        self.futures[future.key] = future
        return future

    def filter(self, record: logging.LogRecord) -> bool:
        if not str(record.msg).startswith("Couldn't gather"):
            return True
        args = record.args if isinstance(record.args, tuple) else ()
        mine = [key for key in (args[1] if len(args) == 2 else ()) if key in self.futures]
        if not mine:
            return True  # not a result of this fit: not ours to count, nor to hide
        now = self.clock()
        for key in mine:
            n = self.failures[key] = self.failures.get(key, 0) + 1
            since = now - self.first_failed.setdefault(key, now)
            if n >= GATHER_TRIES and since >= GATHER_PATIENCE_S and key not in self.cancelled:
                self.cancelled.add(key)
                future = self.futures[key]
                self.client.loop.add_callback(  # on the client's loop: no waiting
                    lambda f=future: self.client.cancel(
                        [f], asynchronous=True, reason=GATHER_FAILED
                    )
                )
        return False


@contextmanager
def _gathers_watched(
    client: Any, clock: Callable[[], float] = time.monotonic
) -> Iterator[_GatherWatch]:
    """:class:`_GatherWatch` (measuring by ``clock``) on the Dask client's logger for the
    length of the block."""
    watch = _GatherWatch(client, clock)
    logger = logging.getLogger("distributed.client")
    logger.addFilter(watch)
    try:
        yield watch
    finally:
        logger.removeFilter(watch)


def _unreachable(address: str, what: str, kept: str) -> str:
    """What is said of a result that could not be fetched :data:`GATHER_TRIES` times."""
    return (
        f"the Dask cluster at {address!r} computed {what} but its result could not be fetched "
        f"from the worker holding it ({GATHER_TRIES} tries over {GATHER_PATIENCE_S:.0f} s): "
        "every worker's own address must "
        "be reachable from the scheduler and from this machine (a firewall, or a worker "
        "listening on an address only its host can reach: see `dask worker --listen-address` "
        f"and `--contact-address`); {kept}"
    )


@dataclass(frozen=True)
class Cluster:
    """A client of the Dask scheduler at ``address``, the ``workers`` whose rti-rig was
    checked (:func:`_refuse_other_code`) before any task was sent, and the resource ``tag``
    that every worker process checked to run this rti-rig holds
    (:func:`rti_rig.app.usecases.worker_code.tagging_plugin`).

    Why a resource, not the addresses: a worker that joins later (restarted with another
    rti-rig, a colleague's added) had been given tasks unchecked. Tasks were then kept to the
    checked addresses, but an address is not a worker: one restarted by its nanny comes back
    on another (the fit stopped, the same code there), one restarted on a fixed port with
    other code has the same (it was given tasks). The tag is given by the worker process
    itself, once its own code is found to be this one, as it joins; every task needs it
    (:meth:`restrictions`)."""

    client: Any
    address: str
    workers: frozenset[str]
    tag: str
    #: the name of this fit's tagging plugin on the scheduler (asked why a worker is untagged)
    plugin: str = ""

    def restrictions(self) -> dict[str, Any]:
        """The keywords of ``Client.submit`` / ``Client.compute`` that keep a task to the
        workers checked to run this rti-rig."""
        return {"resources": {self.tag: 1}}


def workers_by_tag(cluster: Cluster) -> tuple[set[str], set[str]]:
    """The workers of the cluster now that hold :attr:`Cluster.tag` (checked to run this
    rti-rig) and those that do not (another rti-rig, or none)."""
    workers = cluster.client.scheduler_info(n_workers=-1)["workers"]
    tagged = {w for w, info in workers.items() if cluster.tag in (info.get("resources") or {})}
    return tagged, set(workers) - tagged


def checked_gone(cluster: Cluster, kept: str) -> str:
    """What is said when no worker checked to run this rti-rig has been in the cluster for
    :data:`CHECKED_GRACE_S` (the tasks wait for no one), naming the workers there and why each
    holds no tag: other code, or a check that failed on a worker still there (which had been
    said to have left)."""
    try:
        others: set[str] | None = workers_by_tag(cluster)[1]
    except Exception:  # the scheduler lost meanwhile: who is there is not known
        others = None
    # a worker of another Python (joined after the check) is refused in the check's words,
    # naming both versions, asked of Dask's own report: the tag check's "other code" (or "the
    # rti-rig check was never set up there", where our functions cannot run) named neither
    ours = dict(local_identity().stack).get(PYTHON, "")
    pythons = worker_pythons(cluster.client) if others and ours else {}
    other_python = {w: v for w, v in pythons.items() if w in (others or ()) and v != ours}
    rest = None if others is None else others - set(other_python)
    why: dict[str, Untagged] = {}
    if rest:
        try:
            why = plugin_outcomes(cluster.client, cluster.plugin, sorted(rest))
        except Exception:  # the scheduler lost meanwhile: the workers are named alone
            why = {}
    failed = sorted(w for w, o in why.items() if not o.other_code)
    named = ", ".join(f"{w} ({why[w].reason})" if w in why else w for w in sorted(rest or ()))
    if rest is None:  # not "no worker is there now": the scheduler did not say
        there = "which workers are there now is not known (the scheduler did not answer)"
    elif failed:
        there = "the workers there now were not tagged, the rti-rig check failing on "
        there += f"{', '.join(failed)} (see their logs, restart them): {named}"
    elif rest:
        there = f"the workers there now were refused, their rti-rig being another or none: {named}"
    elif other_python:
        there = ""
    else:
        there = "no worker is there now"
    if other_python:
        lead = f"{len(other_python)} of the {len(others or ())} workers there now"
        python = other_python_said(
            other_python, ours, cluster.address, lead, "they were given no task"
        )
        there = f"{there}; {python}" if there else python
    lead = (
        f"the {len(cluster.workers)} worker(s) of the Dask cluster at {cluster.address!r} whose "
        "rti-rig was checked when the fit began have all left it"
        if not failed
        else f"no worker of the Dask cluster at {cluster.address!r} holds the tag of this "
        "rti-rig any longer"
    )
    return (
        f"{lead}, and no worker running this "
        f"rti-rig ({describe(local_identity())}) joined in the {CHECKED_GRACE_S:.0f} s after; "
        f"{there}. A worker is checked as it joins and given tasks only if it runs this same "
        f"rti-rig, so the fit cannot go on: {kept}; run the same command again once workers "
        "running this rti-rig are back"
    )


class _CheckedWatch:
    """Cancels the tracked futures, with the reason :data:`CHECKED_GONE`, once no worker
    checked to run this rti-rig (holding :attr:`Cluster.tag`) has been in the cluster for
    :data:`CHECKED_GRACE_S`: a task that needs one (:meth:`Cluster.restrictions`) would
    otherwise wait, and the fit with it, for ever. Looks every :data:`CHECKED_POLL_S` seconds
    in a thread of its own, stopped at the end of the block."""

    def __init__(self, cluster: Cluster, watch: _GatherWatch) -> None:
        self.cluster = cluster
        self.watch = watch
        self.stop = threading.Event()
        self.gone = False
        self.thread = threading.Thread(target=self._run, name="rti-rig-checked", daemon=True)

    def _tagged_present(self) -> bool:
        try:
            return bool(workers_by_tag(self.cluster)[0])
        except Exception:  # the scheduler lost: said by the waiting code, in its words
            return True

    def _run(self) -> None:
        cancelled: set[Any] = set()
        absent_since: float | None = None
        while not self.stop.wait(CHECKED_POLL_S):
            if not self.gone:
                if self._tagged_present():
                    absent_since = None
                else:
                    now = time.monotonic()
                    absent_since = now if absent_since is None else absent_since
                    self.gone = now - absent_since >= CHECKED_GRACE_S
            if self.gone:  # and again at each look: a task sent meanwhile waits too
                waiting = [
                    f
                    for key, f in list(self.watch.futures.items())
                    if key not in cancelled and f.status == "pending"
                ]
                cancelled.update(f.key for f in waiting)
                if waiting:
                    self._cancel(waiting)

    def _cancel(self, futures: list[Any]) -> None:
        """Cancel ``futures`` with :data:`CHECKED_GONE`, on the client's loop (no waiting)."""
        client = self.cluster.client
        client.loop.add_callback(
            lambda: client.cancel(futures, asynchronous=True, reason=CHECKED_GONE)
        )


@contextmanager
def _checked_watched(cluster: Cluster, watch: _GatherWatch) -> Iterator[_CheckedWatch]:
    """:class:`_CheckedWatch` over ``watch``'s futures for the length of the block."""
    checked = _CheckedWatch(cluster, watch)
    checked.thread.start()
    try:
        yield checked
    finally:
        checked.stop.set()
        checked.thread.join(timeout=CONNECT_TIMEOUT_S)  # a look may await the scheduler


@contextmanager
def scheduler_client(address: str) -> Iterator[Cluster | None]:
    """A ``distributed.Client`` connected to ``address`` (closed afterwards) with the workers
    it checked (:class:`Cluster`), or None for :data:`THREADS`. Refuses clearly when the
    scheduler does not answer within :data:`CONNECT_TIMEOUT_S` or has no workers within
    :data:`WORKERS_TIMEOUT_S`."""
    if address == THREADS:
        yield None
        return
    from distributed import Client

    target, security = address, None
    if checked_address(address) != "inproc":  # one only in this process: nothing can hang
        reached = probe(address, CONNECT_TIMEOUT_S)  # its host not looked up again by Dask
        target, security = reached.address, reached.security()
    try:
        with _version_mismatch_held() as held:
            client = Client(
                target, timeout=CONNECT_TIMEOUT_S, set_as_default=False, security=security
            )
    except (OSError, TimeoutError, ValueError, TypeError) as exc:
        raise unreachable_scheduler(address, f"{type(exc).__name__}: {exc}") from None
    with _reconnect_failure_unlogged(), _cluster_of(client, address, held) as cluster:
        yield cluster


@contextmanager
def _version_mismatch_held() -> Iterator[list[warnings.WarningMessage]]:
    """Dask's "Mismatched versions found" warning, raised as the ``Client`` connects, kept
    back in the list yielded (every other warning is let through as it came).

    Why: a worker of another distributed is refused by this command in its own words, naming
    the worker, its versions and what to install (:func:`_refuse_other_libraries`); Dask's
    table had been printed first as a note, a second account of it in another voice. Said
    once the workers pass the checks: then it names libraries this command does not compare."""
    from distributed.versions import VersionMismatchWarning

    held: list[warnings.WarningMessage] = []
    caught: list[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as recorded:
            warnings.simplefilter("always", VersionMismatchWarning)
            caught = recorded or []
            yield held
    finally:  # a Client that failed to connect lets the others through too
        _let_through(caught, held, VersionMismatchWarning)


def _let_through(
    caught: list[warnings.WarningMessage], held: list[warnings.WarningMessage], kept: type
) -> None:
    """Warn again the ``caught`` warnings, but those of category ``kept``, added to ``held``."""
    for record in caught:
        if issubclass(record.category, kept):
            held.append(record)
        else:
            warnings.warn_explicit(record.message, record.category, record.filename, record.lineno)


def _say_held(held: list[warnings.WarningMessage]) -> None:
    """Raise again the warnings :func:`_version_mismatch_held` kept back."""
    for record in held:
        warnings.warn(record.message, stacklevel=2)


@contextmanager
def _reconnect_failure_unlogged() -> Iterator[None]:
    """Dask's "Failed to reconnect to scheduler" log line kept off the user's terminal.

    Why: a scheduler lost mid-fit is said by this command in its own words ("lost the Dask
    scheduler at …"); Dask's client first logged it as a timestamped ERROR line on stderr, a
    second account of the same event in another voice."""
    log = logging.getLogger("distributed.client")
    dropped = _DropReconnectFailure()
    log.addFilter(dropped)
    try:
        yield
    finally:
        log.removeFilter(dropped)


class _DropReconnectFailure(logging.Filter):
    def filter(self, record: logging.LogRecord) -> bool:
        return not str(record.msg).startswith("Failed to reconnect to scheduler")


@contextmanager
def _cluster_of(
    client: Any, address: str, held: list[warnings.WarningMessage] | None = None
) -> Iterator[Cluster]:
    """The :class:`Cluster` of a connected ``client``: workers waited for and checked, the
    tagging plugin registered (removed afterwards); the client closed at the end. ``held``:
    Dask's version warnings, said once the workers passed the checks (see
    :func:`_version_mismatch_held`)."""
    try:
        try:
            client.wait_for_workers(1, timeout=WORKERS_TIMEOUT_S)
        except (TimeoutError, OSError):
            raise SchedulerError(
                f"the Dask scheduler at {address!r} has no workers after "
                f"{WORKERS_TIMEOUT_S:.0f} s: start some with `dask worker {address}`; "
                f"{SHARED_PATHS}."
            ) from None
        checked = _refuse_other_code(client, address)
        _say_held(held or [])
        mine = local_identity()
        _remove_stale_plugins(client)
        # This fit's, named after its client: removed after it, or by a later fit once this
        # client is gone from the scheduler (killed before it could remove it).
        plugin_name = f"{PLUGIN_PREFIX}{client.id}"
        try:
            # A worker lost during the registration fails it (Dask's CommClosedError), but the
            # scheduler keeps the plugin before telling the workers, so every worker that joins
            # is still checked; one lost now is not tagged, given no task. A scheduler lost is
            # said by the waiting code, and no tagged worker by _CheckedWatch, in their words.
            with suppress(Exception):
                client.register_plugin(tagging_plugin(mine), name=plugin_name)
            cluster = Cluster(client, address, checked, tag_for(mine), plugin_name)
            _refuse_none_tagged(cluster)
            yield cluster
        finally:
            with suppress(Exception):  # the scheduler lost: it took the plugin with it
                client.unregister_worker_plugin(plugin_name)
    finally:
        _close_quietly(client)


#: The name of a fit's worker plugin, before its client's id (``Client-…``). Plugins named
#: ``rti-rig-code-check-`` followed by 32 hex digits (before 2026-12-01) named no client.
PLUGIN_PREFIX = "rti-rig-code-check-"


def _remove_stale_plugins(client: Any) -> None:
    """Remove from the scheduler the tagging plugins of fits whose client is gone.

    Why: a fit removes its plugin when it ends, but a client killed (SIGKILL, a lost machine)
    cannot, and the scheduler kept the plugin for ever: every worker joining later ran it (an
    rti-rig check of other code, its tag, its pause and resume), plugins of older rti-rig
    versions included, each fit adding one. A plugin is this fit's if its name holds the id of
    a client the scheduler still has; any other with :data:`PLUGIN_PREFIX` is stale. Asked on
    the scheduler (``run_on_scheduler``, a nested function sent by value); a scheduler that
    refuses it (``distributed.scheduler.pickle`` off) keeps them, as before."""
    prefix = PLUGIN_PREFIX

    def stale(dask_scheduler: Any) -> list[str]:
        clients = [c for c in dask_scheduler.clients if c.startswith("Client-")]
        return [
            name
            for name in dask_scheduler.worker_plugins
            if name.startswith(prefix) and not any(name == prefix + c for c in clients)
        ]

    try:
        names = client.run_on_scheduler(stale)
    except Exception:  # pickled functions refused there, or the scheduler lost: kept
        return
    for name in names:
        with suppress(Exception):  # removed meanwhile by another fit
            client.unregister_worker_plugin(name)


def _refuse_none_tagged(cluster: Cluster) -> None:
    """Refuse, naming each worker and what failed there, a cluster where no worker holds the
    tag once the plugin is registered although the checked workers are there.

    Why: a check that fails on a worker still there (its resource refused by the scheduler,
    its files unreadable) leaves it untagged; with none tagged the fit waited
    :data:`CHECKED_GRACE_S`, then said every checked worker had left the cluster."""
    try:
        tagged, untagged = workers_by_tag(cluster)
    except Exception:  # the scheduler lost: said by the waiting code, in its words
        return
    present = untagged & cluster.workers
    if tagged or not present:
        return  # a worker to run the tasks, or the checked ones gone: _CheckedWatch's to say
    try:
        why = plugin_outcomes(cluster.client, cluster.plugin, sorted(present))
    except Exception:  # the scheduler lost: said by the waiting code, in its words
        return
    failed = {w: o.reason for w, o in why.items() if not o.other_code}
    if not failed:  # replaced by workers of other code: _CheckedWatch's to say, as refused
        return
    named = "; ".join(f"{w} ({o})" for w, o in sorted(failed.items()))
    raise SchedulerError(
        f"the rti-rig check could not tag any of the {len(present)} worker(s) of the Dask "
        f"cluster at {cluster.address!r} checked to run this rti-rig "
        f"({describe(local_identity())}), though they are still in it: {named}. Nothing was "
        "sent: see those workers' logs, restart them (`dask worker ADDRESS`), and run the "
        "same command"
    )


def _refuse_other_code(client: Any, address: str) -> frozenset[str]:
    """Refuse a cluster whose workers run another rti-rig than this machine, before any task
    is sent (:mod:`rti_rig.app.usecases.worker_code` says why); the workers checked."""
    mine = local_identity()
    if mine.problem is not None:  # this process's own code is not its files' any more
        raise SchedulerError(
            f"this machine's {describe(mine)}: the workers cannot be checked against the code "
            "this command runs. Nothing was sent: run the same command again"
        )
    asked = _refuse_other_python(client, mine, address)  # before any function of ours runs
    workers = worker_identities(client)
    if set(workers) - asked:  # joined meanwhile (or missed by the report): asked in its words
        _refuse_other_python(client, mine, address, asked)
    _refuse_other_libraries(workers, mine, address)
    untold = {w: ident for w, ident in workers.items() if isinstance(ident, Unasked)}
    differ = {
        w: ident
        for w, ident in workers.items()
        if isinstance(ident, WorkerCode) and not ident.same_code(mine)
    }
    if differ:
        named = "; ".join(f"{w} ({describe(ident)})" for w, ident in sorted(differ.items()))
        raise SchedulerError(
            f"{len(differ)} of the {len(workers)} workers of the Dask cluster at {address!r} "
            f"run other rti-rig code than this machine ({describe(mine)}): {named}. Their "
            "tasks and results cannot be read from one side to the other, so nothing was "
            "sent: install this same rti-rig on every worker (the same release, or the same "
            "checkout installed with `pip install -e`), restart the workers, and run the same "
            "command"
        )
    if untold:
        named = "; ".join(f"{w} ({why.reason})" for w, why in sorted(untold.items()))
        raise SchedulerError(
            f"{len(untold)} of the {len(workers)} workers of the Dask cluster at {address!r} "
            f"could not be asked which rti-rig they run: {named}. Nothing was sent: check "
            "that they are running and reachable from this machine (restart them), and run "
            f"the same command; they must run this same rti-rig ({describe(mine)})"
        )
    return frozenset(workers)


def _refuse_other_python(
    client: Any, mine: WorkerCode, address: str, asked: frozenset[str] = frozenset()
) -> frozenset[str]:
    """Refuse a cluster some of whose workers run another Python minor version than this
    machine (:data:`~rti_rig.app.usecases.worker_code.PYTHON` says why), naming each, both
    versions and what to do; asked of Dask's own version report, before the rti-rig check
    (a function pickled by value) is sent to them. The workers whose Python was asked (found
    the same), with ``asked`` (those asked before, not judged again).

    Why: the workers' distributed, dask, cloudpickle and numpy were compared, not their
    Python, and cloudpickle's functions of a 3.11 client failed on a 3.12 worker in ways that
    named no version (the check itself "could not be asked", or the worker died)."""
    ours = dict(mine.stack).get(PYTHON, "")
    pythons = worker_pythons(client)
    differ = {w: v for w, v in pythons.items() if ours and v != ours and w not in asked}
    if not differ:
        return asked | frozenset(pythons)
    total = len(set(pythons) | asked)
    lead = f"{len(differ)} of the {total} workers of the Dask cluster at {address!r}"
    raise SchedulerError(
        f"{other_python_said(differ, ours, address, lead, 'nothing was sent')}, and run the "
        "same command"
    )


def other_python_said(differ: dict[str, str], ours: str, address: str, lead: str, sent: str) -> str:
    """The words that refuse the workers of ``differ`` (address: their Python minor version)
    for running another Python than this machine's ``ours``: ``lead`` (who), both versions,
    why, ``sent`` (what became of the fit's tasks) and what to do. One wording for a worker
    found at the check and one joining after it (:func:`checked_gone`): a late joiner had
    been said only as "other code" by the tag check, its Python unnamed."""
    named = "; ".join(f"{w} (Python {v})" for w, v in sorted(differ.items()))
    return (
        f"{lead} run another Python than this machine (Python {ours}): {named}. The fit's "
        f"functions travel to the workers as Python {ours}'s byte code (cloudpickle), which "
        "another Python minor version cannot run (such a worker fails or dies with errors "
        f"that name no version), so {sent}: run those workers under Python {ours} (an "
        f"environment made with python{ours}, this rti-rig and the same distributed, dask, "
        f"cloudpickle and numpy installed in it, then `dask worker {address}` from it)"
    )


def _refuse_other_libraries(
    workers: dict[str, WorkerCode | Unasked], mine: WorkerCode, address: str
) -> None:
    """Refuse a cluster some of whose workers run other versions of the libraries the fit's
    tasks travel through (:data:`~rti_rig.app.usecases.worker_code.STACK_PACKAGES`), naming
    each such worker, the versions that differ, and the ones to install.

    Why: a worker of another distributed was let through (its rti-rig was this one); Dask
    printed its "Mismatched versions found" table as a note, the worker died on its first
    task (``TypeError: ComputeTaskEvent…``) and about 80 s later the fit said the checked
    workers "have all left", exit 2, without saying why. Checked before the rti-rig code:
    such a worker cannot run this fit whatever rti-rig it has."""
    differ = {
        w: found
        for w, ident in workers.items()
        if isinstance(ident, WorkerCode) and (found := stack_differences(mine, ident))
    }
    if not differ:
        return
    named = "; ".join(
        f"{w} ({', '.join(describe_library(name, theirs) for name, _, theirs in found)})"
        for w, found in sorted(differ.items())
    )
    needed = {name: ours for found in differ.values() for name, ours, _ in found}
    ours_said = ", ".join(describe_library(name, version) for name, version in needed.items())
    pins = " ".join(
        f"'{name}=={version.removesuffix('.x')}{'.*' if version.endswith('.x') else ''}'"
        for name, version in needed.items()
        if version and name != PYTHON  # no pip install gives another Python
    )
    todo = f"install these versions on those workers (pip install {pins})" if pins else ""
    if needed.get(PYTHON):  # a worker Dask's own report left out (_refuse_other_python)
        under = f"run those workers under Python {needed[PYTHON]}"
        todo = f"{under}, with {todo.removeprefix('install ')}" if todo else under
    raise SchedulerError(
        f"{len(differ)} of the {len(workers)} workers of the Dask cluster at {address!r} run "
        f"other versions of the libraries this fit's tasks pass through than this machine "
        f"({ours_said}): {named}. Dask's client and workers must run the same distributed, "
        "dask and cloudpickle, the same major numpy and the same Python minor version (their "
        "tasks and results cannot be read from one side to the other: such a worker dies on "
        f"its first task), so nothing was sent: {todo}, restart them, and run the same command"
    )


def _close_quietly(client: Any) -> None:
    """Close ``client`` without Dask's log lines reaching the user.

    Why: closing a client that has lost its scheduler cancels its reconnection attempt, which
    Dask logs as an ERROR with a full traceback (``CancelledError`` in ``_reconnect``) on
    stderr, after the error this command reports in its own words."""
    from distributed.utils import silence_logging_cmgr

    with silence_logging_cmgr(logging.CRITICAL):
        client.close()


def scheduler_lost(client: Any, exc: BaseException) -> bool:
    """Whether ``exc``, raised by a future's result, means the scheduler went away: Dask then
    cancels every future of the client (even finished ones whose result was not fetched yet)
    with the reason :data:`SCHEDULER_LOST`; an ``OSError`` may come from a connection cut
    mid-transfer. A lost scheduler had been reported as a failed band ("check the workers'
    logs (memory limit?)"), and in a batch as every session failed, finished ones too."""
    if isinstance(exc, OSError) or getattr(exc, "reason", None) == SCHEDULER_LOST:
        return True
    return str(getattr(client, "status", "running")) in ("connecting", "closing", "closed")


def dask_bands(cluster: Cluster | None, source: Path) -> BandRunner:
    """A band runner for :func:`rti_rig.app.usecases.fit.run_fit`: the bands of ``source`` as
    chunks of a lazily read ``dask.array``, each fitted by :func:`fit_band` — in threads here
    (``cluster`` None) or on the checked workers of ``cluster``."""

    def run(
        stack: ImageStack, plan: BandPlan, tiles: list[slice]
    ) -> Iterator[tuple[slice, BandFit]]:
        import dask

        _, _, paths, _ = acquisition_files(source)
        array = lazy_stack(StackSource.of(paths, stack, read_image), plan.tile_rows)
        blocks = array.to_delayed().ravel()  # one per band, in row order
        if len(blocks) != len(tiles):
            raise AssertionError(f"{len(blocks)} chunks for {len(tiles)} bands")
        if cluster is None:
            tasks = [dask.delayed(fit_band, pure=True)(b, plan) for b in blocks]
            yield from _in_threads(tasks, tiles)
        else:
            threads = blas_threads()
            tasks = [dask.delayed(fit_band_recording, pure=True)(b, plan, threads) for b in blocks]
            yield from _on_cluster(cluster, tasks, tiles)

    return run


def _in_threads(tasks: list[Any], tiles: list[slice]) -> Iterator[tuple[slice, BandFit]]:
    """Band fits computed in local threads (one per core), a bounded number in flight, yielded
    as they finish: each band's graph (read the chunk, fit it) runs in a pool thread."""
    import dask

    threads = os.cpu_count() or 2
    pending = iter(range(len(tasks)))
    running: dict[Future[Any], int] = {}
    pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="dask-band")

    def submit_next() -> None:
        i = next(pending, None)
        if i is not None:
            running[pool.submit(dask.compute, tasks[i], scheduler="sync")] = i

    try:
        for _ in range(BANDS_IN_FLIGHT_PER_THREAD * threads):
            submit_next()
        while running:
            done, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in done:
                i = running.pop(future)
                (fitted,) = future.result()
                yield tiles[i], fitted
                submit_next()
    finally:  # the caller stopped early or failed: drop what has not started
        pool.shutdown(wait=True, cancel_futures=True)


def _on_cluster(
    cluster: Cluster, tasks: list[Any], tiles: list[slice]
) -> Iterator[tuple[slice, BandFit]]:
    """Band fits computed on the cluster's checked workers, a bounded number in flight,
    yielded as they finish."""
    from distributed import as_completed

    client, address = cluster.client, cluster.address

    threads = max(1, sum(client.nthreads().values()))
    window = BANDS_IN_FLIGHT_PER_THREAD * threads
    pending = iter(range(len(tasks)))
    outstanding: dict[Any, tuple[Any, int]] = {}

    def submit_next(watch: _GatherWatch) -> Any:
        i = next(pending, None)
        if i is None:
            return None
        future = watch.track(client.compute(tasks[i], **cluster.restrictions()))
        outstanding[future.key] = (future, i)
        return future

    with _gathers_watched(client) as watch, _checked_watched(cluster, watch):
        first = [f for f in (submit_next(watch) for _ in range(window)) if f is not None]
        running = as_completed(first, loop=client.loop)
        try:
            for future in running:
                try:
                    fitted = future.result()
                except ImageReadError as exc:
                    raise SchedulerError(
                        f"a worker of the Dask cluster at {address!r} could not read the "
                        f"images: {exc}. Note: {SHARED_PATHS}."
                    ) from None
                except RtiRigError:
                    raise  # a named error of the fit itself, raised on the worker
                except Exception as exc:  # e.g. KilledWorker: a worker died on this band
                    raise _band_failed(cluster, exc) from None
                yield tiles[outstanding.pop(future.key)[1]], fitted
                future.release()
                following = submit_next(watch)
                if following is not None:
                    running.add(following)
        finally:  # the caller stopped early or failed: cancel what is left
            running.clear()
            if outstanding:
                client.cancel([f for f, _ in outstanding.values()])


def _band_failed(cluster: Cluster, exc: BaseException) -> SchedulerError:
    """The error of a band whose future failed (a lost scheduler, a result that could not
    be fetched, or no checked worker left, said as such)."""
    client, address = cluster.client, cluster.address
    if getattr(exc, "reason", None) == CHECKED_GONE:
        return SchedulerError(checked_gone(cluster, "nothing of this fit was kept in --out"))
    if getattr(exc, "reason", None) == GATHER_FAILED:
        kept = "nothing of this fit was kept in --out"
        return SchedulerError(_unreachable(address, "a band of the fit", kept))
    if scheduler_lost(client, exc):
        return _fit_lost(address)
    return SchedulerError(
        f"a band of the fit failed on the Dask cluster at {address!r}: "
        f"{type(exc).__name__}: {exc}. Check the workers' logs (memory limit?) and run again; "
        "finished outputs are not kept for a single-session fit"
    )


def _fit_lost(address: str) -> SchedulerError:
    """The error of a single-session fit whose scheduler went away."""
    return SchedulerError(
        f"lost the Dask scheduler at {address!r} while fitting (it stopped or the network "
        "to it failed); nothing of this fit was kept in --out: start the scheduler again "
        f"(`dask scheduler`, workers with `dask worker {address}`) and run the same command"
    )


def run_fit_dask(req: FitRequest, scheduler: str = THREADS) -> FitResult:
    """:func:`run_fit` with its bands computed by Dask (``scheduler``: :data:`THREADS` or a
    scheduler address).

    A scheduler lost before the first band is sent (while this process reads the sample and
    chooses the model) surfaces from a client call, not from a band's result: Dask's client
    retries for its timeout, then raises ``CommClosedError`` (an ``OSError``). Until
    2026-12-01 that reached the user as a 120-line traceback (exit 1)."""
    with scheduler_client(scheduler) as cluster:
        try:
            return run_fit(req, bands=dask_bands(cluster, req.source))
        except OSError as exc:  # output write failures are named by run_fit, not OSError
            if cluster is None or not _comm_lost(cluster.client, exc):
                raise
            raise _fit_lost(cluster.address) from None


def _comm_lost(client: Any, exc: OSError) -> bool:
    """Whether ``exc``, raised by a call on ``client``, is its connection to the scheduler
    gone (stricter than :func:`scheduler_lost`, which takes any ``OSError`` of a band's
    result as one: here a local file error must stay itself)."""
    from distributed.comm.core import CommClosedError

    return isinstance(exc, CommClosedError) or str(getattr(client, "status", "running")) in (
        "connecting",
        "closing",
        "closed",
    )


_SESSION_LOCK = threading.Lock()


def _fit_one_task(source: Path, root: Path, template: FitRequest, threads: int | None) -> BatchItem:
    """One session of a batch, on a worker, with ``threads`` BLAS threads (the client's: see
    :func:`rti_rig.app.usecases.fit_bands.fit_band_recording`). One session at a time per
    worker process: a fit records its warnings with ``warnings.catch_warnings``, which is
    process-wide state, so two sessions in two threads of one process would mix them up."""
    from threadpoolctl import threadpool_limits

    if not source.exists():
        return BatchItem(
            source,
            batch_out_dir(root, source),
            Outcome.FAILED,
            f": {shown_path(source)} does not exist on worker host {socket.gethostname()}: "
            f"{SHARED_PATHS}",
        )
    with _SESSION_LOCK, threadpool_limits(limits=threads, user_api="blas"):
        item = fit_one(source, root, template)
    return replace(item, notes=(*item.notes, _ran_on()))


def _ran_on() -> str:
    """The note saying which worker ran a batch's session (run there). Why: tasks go to any
    worker checked to run this rti-rig, those that join or restart later too, so the user is
    told which one fitted each session."""
    from distributed import get_worker

    try:
        address = get_worker().address
    except ValueError:  # not in a worker (a test calling the task here)
        address = "(not a worker)"
    return (
        f"ran on the Dask worker at {address} (host {socket.gethostname()}), checked to run "
        f"this rti-rig ({describe(local_identity())})"
    )


def _finished_kept(sources: list[Path], given: list[tuple[Path, Path]], root: Path) -> str:
    """Which sessions of a stopped batch are finished in ``root`` (a session can finish on its
    worker while the client waits for another's result, so it is told by its folder, not by
    its future, which is cancelled with the rest)."""
    finished = [g for s, g in given if batch_out_dir(root, s).exists()]
    return (
        f"{len(finished)} of {len(sources)} sessions are finished in {shown_path(root)} "
        f"({', '.join(map(shown_path, finished))}) and are kept"
        if finished
        else f"no session is finished in {shown_path(root)} yet"
    )


def _batch_checked_gone(
    cluster: Cluster, sources: list[Path], given: list[tuple[Path, Path]], root: Path
) -> str:
    """What a batch says when every checked worker has left (:func:`checked_gone`)."""
    kept = _finished_kept(sources, given, root)
    return checked_gone(cluster, f"{kept}, the rest are skipped or redone by that run")


def _batch_lost(
    scheduler: str, sources: list[Path], given: list[tuple[Path, Path]], root: Path
) -> SchedulerError:
    """The error of a batch whose scheduler went away: which sessions are finished in
    ``root`` (:func:`_finished_kept`), and that those a worker had begun may still finish.

    Why the latter: a worker goes on with its running task after the scheduler is lost, until
    it shuts down. Killed mid-batch, the scheduler's loss was said as "no session is finished
    in ROOT yet", and 13 s later the session its worker was fitting stood finished in ROOT."""
    kept = _finished_kept(sources, given, root)
    return SchedulerError(
        f"lost the Dask scheduler at {scheduler!r} during the batch (it stopped or the network "
        f"to it failed): {kept}; a session a worker had already begun may still finish there "
        f"and appear in {root} (a worker goes on with its task until it shuts down). Start "
        "the scheduler again (`dask scheduler`, workers with "
        f"`dask worker {scheduler}`) and run the same command to fit the rest: finished "
        "sessions are skipped, partial ones redone"
    )


def run_batch_dask(
    sources: list[Path], root: Path, template: FitRequest, scheduler: str = THREADS
) -> list[BatchItem]:
    """A resumable batch (see :func:`rti_rig.app.usecases.fit_batch.run_batch`) on Dask: with
    :data:`THREADS`, sessions one after another with their bands in threads; on a cluster,
    every unfinished session a task of its own (run in parallel across the workers). A
    ``root`` inside a session folder is refused before the cluster is reached."""
    refuse_out_inside_a_session(root)  # as given, as run_batch does
    if scheduler == THREADS:
        said = prepare_batch(sources, root)  # each session is judged at its turn (fit_one)
        items = [fit_one(s, root, template, bands=dask_bands(None, s)) for s in sources]
        return with_notes(items, said)
    # Absolute, as workers do not share this process's working directory, but not resolved:
    # ``resolve()`` followed a symlinked session folder, so its output was named after the
    # link's target (OUT/s1 for sess/coin_day2 -> s1, OUT/coin_day2 without Dask, so a rerun
    # either way fitted it again), and two spellings of one session (sess/s1, ./sess/s1) were
    # merged into one fit silently where the batch without Dask refuses them.
    given = list(zip([Path(os.path.abspath(s)) for s in sources], sources, strict=True))
    sources = [a for a, _ in given]
    root = root.resolve()
    with scheduler_client(scheduler) as cluster:
        assert cluster is not None  # an address, not THREADS
        client = cluster.client
        said = prepare_batch(sources, root)  # refuses a source given twice, as without Dask
        plan = plan_batch(sources, root)
        threads = blas_threads()
        # A source missing here too is the user's typo, not the workers' filesystem: it is
        # refused here in the words of the batch without Dask ("does not exist: give a session
        # folder or an .lp file"); it had been sent and blamed on the workers' shared paths.
        with _gathers_watched(client) as watch, _checked_watched(cluster, watch) as checked:

            def submit(s: Path) -> Any:
                if checked.gone:  # its task would wait for no one
                    raise SchedulerError(_batch_checked_gone(cluster, sources, given, root))
                task = client.submit(
                    _fit_one_task, s, root, template, threads, pure=False, **cluster.restrictions()
                )
                return watch.track(task)

            futures = {
                s: submit(s) for s, earlier in plan.items() if not earlier.stands and s.exists()
            }
            items = _batch_results(cluster, sources, given, root, template, plan, futures, submit)
        items = with_notes(items, said)
        return [replace(item, source=g) for item, (_, g) in zip(items, given, strict=True)]


def _batch_results(
    cluster: Cluster,
    sources: list[Path],
    given: list[tuple[Path, Path]],
    root: Path,
    template: FitRequest,
    plan: dict[Path, EarlierFit],
    futures: dict[Path, Any],
    submit: Callable[[Path], Any],
) -> list[BatchItem]:
    """Each session's item of a batch on a cluster, in the order given, as its task ends.

    A session :func:`plan_batch` found standing is judged again at its turn (as
    :func:`fit_one` does without Dask): one whose capture was resumed, or an image replaced,
    while the batch ran had been reported "skipped (finished earlier)", its out-of-date fit
    kept. It is then sent (``submit``) and waited for."""
    client, scheduler = cluster.client, cluster.address
    items = []
    for s in sources:
        if not plan[s].stands and s not in futures:
            items.append(fit_one(s, root, template))  # fails at once, naming the path
            continue
        if s not in futures:
            out = batch_out_dir(root, s)
            now = earlier_fit(out, s)
            if now.stands:
                items.append(BatchItem(s, out, Outcome.SKIPPED, now.skip_detail))
                continue
            if not s.exists():  # gone meanwhile: fails at once, naming the path
                items.append(fit_one(s, root, template))
                continue
            futures[s] = submit(s)
        try:
            items.append(futures[s].result())
        except Exception as exc:  # e.g. KilledWorker: this session failed, the batch goes on
            if getattr(exc, "reason", None) == GATHER_FAILED:
                out = batch_out_dir(root, s)
                if out.exists():  # its fit ended on the worker: a rerun skips it as finished
                    outcome, detail = (
                        Outcome.FINISHED,
                        " on its worker; its report could not be fetched (its outputs are in "
                        f"{out})",
                    )
                else:
                    kept = "run the same command again once it is (a finished session is skipped)"
                    outcome = Outcome.FAILED
                    detail = f": {_unreachable(scheduler, 'the session', kept)}"
                items.append(BatchItem(s, out, outcome, detail))
                continue
            if getattr(exc, "reason", None) == CHECKED_GONE:
                raise SchedulerError(_batch_checked_gone(cluster, sources, given, root)) from None
            if scheduler_lost(client, exc):
                raise _batch_lost(scheduler, sources, given, root) from None
            items.append(_task_failed(s, root, exc))
    return items


def _task_failed(source: Path, root: Path, exc: BaseException) -> BatchItem:
    """The item of a session whose task raised ``exc`` on its way back (e.g. a worker died
    on it, or its result could not be read here).

    Why: a result that cannot be read back (a worker running other rti-rig code) raises
    although the session's fit ended on the worker and stands complete in ``--out``: it had
    been said "failed", and the rerun skipped it as "finished earlier". What is known is said:
    a fit that stands is finished, its report unread."""
    out = batch_out_dir(root, source)
    why = f"{type(exc).__name__}: {exc}"
    if earlier_fit(out, source).stands:
        detail = (
            f" on its worker; its report could not be read here ({why}); its fit stands "
            f"complete in {out}"
        )
        return BatchItem(source, out, Outcome.FINISHED, detail)
    return BatchItem(source, out, Outcome.FAILED, f" on the Dask cluster: {why}")
