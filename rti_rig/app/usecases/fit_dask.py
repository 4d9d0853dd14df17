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
files at the same paths as this machine; every error says so.

Dask is imported only here, and this module only when ``--scheduler`` is given.
"""

from __future__ import annotations

import asyncio
import logging
import os
import socket
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from contextlib import contextmanager, suppress
from dataclasses import replace
from pathlib import Path
from typing import Any

from rti_rig.app.usecases.fit import (
    BandRunner,
    FitRequest,
    FitResult,
    acquisition_files,
    read_image,
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
    Outcome,
    batch_out_dir,
    earlier_fit,
    fit_one,
    plan_batch,
)
from rti_rig.core.errors import RtiRigError
from rti_rig.reconstruct.lazy_stack import ImageReadError, StackSource, lazy_stack
from rti_rig.reconstruct.stack import ImageStack

#: ``--scheduler`` value for Dask's threaded scheduler in this process.
THREADS = "threads"
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
#: Failed fetches of one result before the fit stops. Dask retries a failed fetch at once and
#: for ever, logging "Couldn't gather N keys, rescheduling" each time (hundreds a second with
#: a worker that answers the scheduler but not a fetch): one or two are a worker lost and its
#: work done again elsewhere, more a worker whose results cannot be reached.
GATHER_TRIES = 5
#: ... and the least time (seconds) since that result's first failed fetch. Tries alone end
#: too soon: a refused or reset fetch fails 5 times in about half a second, so a network
#: blip of under a second, which Dask rides through, had ended the fit.
GATHER_PATIENCE_S = 60.0


SHARED_PATHS = (
    "every Dask worker must see the session's files at the same paths as this machine "
    "(a shared filesystem mounted at the same place)"
)


class SchedulerError(RtiRigError):
    """The Dask scheduler cannot be used: unreachable, no workers, or workers that cannot read
    the images."""


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


def _unreachable_scheduler(address: str, why: str) -> SchedulerError:
    """What is said of a scheduler that cannot be connected to (``why``: what happened)."""
    return SchedulerError(
        f"cannot reach the Dask scheduler at {address!r} ({why}). "
        f"Start one with `dask scheduler` and workers with `dask worker {address}` — "
        f"{SHARED_PATHS} — or leave out --scheduler to fit in this process."
    )


def _usable(scheme: str) -> bool:
    """Whether Dask's transport for ``scheme`` can open a connection from this process.

    Why: Dask registers ``ucx://`` even without its package (``distributed-ucxx``); a Client
    built on it failed with "TypeError: Can't instantiate abstract class UCXConnector", told as
    a scheduler that could not be reached. Getting the connector is what fails, and costs
    nothing (no connection is opened)."""
    import warnings

    from distributed.comm.registry import get_backend

    try:
        with warnings.catch_warnings():  # the deprecated ucx:// warns as it fails
            warnings.simplefilter("ignore")
            get_backend(scheme).get_connector()
    except Exception:  # any failure means the same: not usable here
        return False
    return True


def _inproc_listening(location: str) -> bool:
    """Whether ``location`` (of an ``inproc://`` address) names a server living in this
    process: only then can it be reached (a test's in-process ``LocalCluster``)."""
    from distributed.comm.inproc import global_manager

    try:
        return global_manager.get_listener_for(location) is not None
    except ValueError:  # not ip/pid/n, or another process's pid or host
        return False


def _checked_address(address: str) -> str:
    """``address``'s scheme, once Dask can parse the address and has a usable transport for it.

    Why: a Client built on an address Dask cannot use raised ValueError (said clearly), but the
    half-built Client then waited 40 s in its ``__del__`` and printed an "Exception ignored …
    TimeoutError" traceback after the error; an ``http://`` address was also advised as the
    one to start workers with. So were ``inproc://`` (a scheduler inside one Python process,
    which no other process can reach: it was listed as accepted and advised for ``dask
    worker``) and ``ucx://`` (listed as accepted, its package not installed)."""
    from distributed.comm import parse_address
    from distributed.comm.addressing import parse_host_port
    from distributed.comm.registry import backends, get_backend

    try:
        scheme, location = parse_address(address)
        if scheme in ("tcp", "tls", "ws", "wss"):
            parse_host_port(location)
    except (ValueError, TypeError) as exc:
        raise SchedulerError(
            f"--scheduler {address!r} is not a Dask scheduler address ({exc}): give "
            f"'{THREADS}' or an address such as tcp://HOST:8786"
        ) from None
    # the transports a scheduler in another process can be reached by, as the user is told
    usable = ", ".join(f"{s}://" for s in sorted(backends) if s != "inproc" and _usable(s))
    give = f"Give '{THREADS}' or the address `dask scheduler` prints, such as tcp://HOST:8786"
    if scheme == "inproc":
        if _inproc_listening(location):
            return scheme
        raise SchedulerError(
            f"--scheduler {address!r} cannot be reached: an inproc:// address names a "
            "scheduler inside one Python process, and no other process (this `rti-rig fit` "
            f"included) can connect to it. {give}, or leave out --scheduler to fit in this "
            "process"
        )
    try:
        get_backend(scheme)  # the transports Dask ships, then any a package registers
    except (ValueError, ImportError):
        raise SchedulerError(
            f"--scheduler {address!r} is not a Dask scheduler address: Dask has no transport "
            f"for {scheme}://, it accepts {usable}. {give}"
        ) from None
    if not _usable(scheme):
        hint = " (the distributed-ucxx package)" if scheme == "ucx" else ""
        raise SchedulerError(
            f"--scheduler {address!r} needs Dask's {scheme}:// transport, which is not "
            f"installed here{hint}; the transports this machine has are {usable}. {give}"
        )
    return scheme


class _Refused(Exception):
    """The scheduler's host refused the connection: nothing listens on that port."""


class _Unresolved(Exception):
    """The resolver said the scheduler's host name has no address (``args``: the host, why)."""


class _LookupFailed(Exception):
    """The scheduler's host name could not be looked up: the resolver did not answer in time,
    or failed for a reason of its own, which is not a name that does not exist (``args``: the
    host, why)."""


#: The resolver's answers that a name has no address: said as "does not resolve". Any other
#: failure (EAI_AGAIN, a nameserver down or slow) says nothing about the name.
NO_SUCH_NAME = tuple(
    code for code in (socket.EAI_NONAME, getattr(socket, "EAI_NODATA", None)) if code is not None
)


def _refused(exc: BaseException | None) -> bool:
    """Whether ``exc``, or an exception it was raised from, is a refused connection (Dask's
    TCP connector raises ``CommClosedError`` from the ``ConnectionRefusedError``)."""
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, ConnectionRefusedError):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


async def _resolve(host: str, port: int, timeout: float) -> list[str]:
    """The addresses ``host`` resolves to, in the resolver's order; raise :class:`_Unresolved`
    when the resolver says it has no address, :class:`_LookupFailed` when it has not answered
    within ``timeout`` seconds or failed otherwise.

    Why: Dask's ``connect`` retries a name that does not resolve until its timeout, so a
    mistyped host waited the full 20 s and was told as "no Dask scheduler answered". The lookup
    runs in a daemon thread: ``getaddrinfo`` cannot be interrupted, and a resolver that hangs
    must hold neither this wait beyond ``timeout`` nor the exit of a stopped ``rti-rig fit``
    (the event loop's own executor is joined at exit). A slow answer is not a missing name:
    the lookup had been cut at a fifth of the connect timeout (4 s), under glibc's 5 s per
    nameserver, so a machine whose first nameserver was down was told that a valid host "does
    not resolve"."""
    loop = asyncio.get_running_loop()
    answer: asyncio.Future[BaseException | list[str]] = loop.create_future()

    def tell(outcome: BaseException | list[str]) -> None:
        if not answer.done():
            answer.set_result(outcome)

    def lookup() -> None:
        outcome: BaseException | list[str]
        try:
            infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
            outcome = list(dict.fromkeys(str(info[4][0]) for info in infos))
        except OSError as exc:  # socket.gaierror, or an OSError of the resolver's
            outcome = exc
        with suppress(RuntimeError):  # the loop is closed: the probe was stopped or timed out
            loop.call_soon_threadsafe(tell, outcome)

    threading.Thread(target=lookup, name="rti-rig-resolve", daemon=True).start()
    try:
        outcome = await asyncio.wait_for(answer, timeout)
    except TimeoutError:
        raise _LookupFailed(host, f"the resolver did not answer within {timeout:.0f} s") from None
    if isinstance(outcome, BaseException):
        why = getattr(outcome, "strerror", None) or str(outcome)
        if isinstance(outcome, socket.gaierror) and outcome.errno in NO_SUCH_NAME:
            raise _Unresolved(host, why)
        raise _LookupFailed(host, why)
    return outcome


def _host_port(address: str) -> tuple[str, int] | None:
    """The host and port of a tcp://, ws://, tls:// or wss:// ``address``; None for others
    (inproc://, ucx://: nothing of theirs is looked up or connected to here)."""
    from distributed.comm import parse_address, parse_host_port

    scheme, location = parse_address(address)
    if scheme not in ("tcp", "ws", "tls", "wss"):
        return None
    host, port = parse_host_port(location)
    return host, int(port)


async def _connect(
    address: str, timeout: float, connection_args: dict[str, Any], ips: Sequence[str] = ()
) -> Any:
    """A Dask comm to ``address``, its handshake done (``distributed.comm.connect``), after
    plain connections to ``ips`` (its host's addresses, looked up before: see :func:`_probe`)
    find a refused port at once.

    Why: Dask's ``connect`` retries a refused connection, and a name that does not resolve,
    until its timeout, so a port nothing listens on (a scheduler not started, a wrong port) or
    a mistyped host waited the full 20 s and was told as "Timed out trying to connect". A
    lookup and a bare connect say it in milliseconds, with nothing of Dask's handshake copied
    here (a copy would break silently with a Dask upgrade); a scheduler that is there logs it
    at INFO as a connection closed before its handshake. For tls:// and wss:// the same
    connect also does the TLS handshake, with the context Dask's own connect uses, so that a
    listener that is there does not log a failed TLS handshake as a warning; a refused port
    fails before any handshake. Any other failure (a certificate refused, a slow network) is
    left to Dask, which says it in its own words. The plain connections go to the addresses
    looked up, not to the name: a slow resolver (a nameserver down, 5 s per lookup) had timed
    out this step's second lookup, and the port is called refused only where every address
    refuses (localhost's ::1 may refuse where 127.0.0.1 listens)."""
    from distributed.comm import connect, parse_address

    scheme, location = parse_address(address)
    host_port = _host_port(address)
    if host_port is not None and ips:
        host, port = host_port
        tls: Any = None
        if scheme == "tls":
            tls = connection_args.get("ssl_context")  # checked by _tls_settings: a context
        elif scheme == "wss":  # Dask's wss:// gives tornado None for its default context
            tls = connection_args.get("ssl_context") or True

        async def every_refused() -> bool:
            for ip in ips:
                try:
                    _, writer = await asyncio.open_connection(
                        ip, port, ssl=tls, server_hostname=host if tls else None
                    )
                except (OSError, ValueError) as exc:
                    if _refused(exc):
                        continue
                    return False
                writer.close()
                return False
            return True

        with suppress(TimeoutError):
            if await asyncio.wait_for(every_refused(), timeout / 5):
                raise _Refused(location)
    return await connect(address, timeout=timeout, **connection_args)


async def _identity(
    address: str, timeout: float, connection_args: dict[str, Any], ips: Sequence[str] = ()
) -> Any:
    """The scheduler's answer to Dask's ``identity`` request (a connection, its handshake, one
    request and its reply); ``ips``: its host's addresses (:func:`_connect`)."""
    comm = await _connect(address, timeout, connection_args, ips)
    try:
        await comm.write({"op": "identity", "reply": True})
        return await comm.read()
    finally:
        comm.abort()


def _run_quietly(main: Any) -> Any:
    """``asyncio.run(main)``, without asyncio's report of the tasks a stop leaves behind.

    Why: a Ctrl-C that lands while the probe connects cancels the connection's tasks, and one
    that ends with an exception of its own (a comm closed under it) was printed by
    ``asyncio.run``'s shutdown as "unhandled exception during asyncio.run() shutdown" with a
    traceback, after "Stopped (Ctrl-C)". And ``asyncio.run`` turns a Ctrl-C into a cancellation
    of its main task, which the connection under way could outlive: under load the stopped
    ``rti-rig fit`` then waited on the silent port for good (a test timed out at 150 s). Here
    the Ctrl-C is raised as it comes, and what it leaves is given one second to end."""
    loop = asyncio.new_event_loop()
    try:
        return loop.run_until_complete(main)
    finally:
        loop.set_exception_handler(lambda _loop, _context: None)
        try:
            left = [task for task in asyncio.all_tasks(loop) if not task.done()]
            for task in left:
                task.cancel()
            if left:  # bounded: a task that ignores its cancellation must not hold the stop
                loop.run_until_complete(asyncio.wait(left, timeout=1.0))
            loop.run_until_complete(loop.shutdown_asyncgens())
        finally:
            loop.close()


#: Dask's configuration keys a tls:// client needs (its ``Security()`` reads them).
TLS_KEYS = (
    "distributed.comm.tls.ca-file",
    "distributed.comm.tls.client.cert",
    "distributed.comm.tls.client.key",
)


def _tls_settings(address: str) -> dict[str, Any]:
    """The connection arguments Dask's ``Client`` will use (``Security()`` from Dask's
    configuration), refused in words when they cannot serve ``address``.

    Why: a tls:// address without TLS settings was told as "cannot reach the Dask scheduler
    (TypeError: TLS expects a `ssl_context` argument …)", with advice to start a scheduler,
    when what is missing is this client's certificate and the CA to check the scheduler's;
    and a certificate file that cannot be read raised out of here with a traceback."""
    import ssl

    import dask.config
    from distributed.security import Security

    how = (
        f"Dask reads them from its configuration: {', '.join(TLS_KEYS)} (the key may be in "
        "the certificate file), in a YAML file under ~/.config/dask/ or as the environment "
        "variables DASK_DISTRIBUTED__COMM__TLS__CA_FILE, "
        "DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT and DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY"
    )
    try:
        security = Security()
        args: dict[str, Any] = security.get_connection_args("client")
    except (OSError, ValueError) as exc:  # ssl.SSLError is an OSError
        given = {key: dask.config.get(key, None) for key in TLS_KEYS}
        named = ", ".join(f"{key} = {value!r}" for key, value in given.items() if value)
        raise SchedulerError(
            f"--scheduler {address!r}: Dask's TLS settings cannot be used "
            f"({type(exc).__name__}: {exc}; {named or 'none given'}). Check the files they "
            f"name; {how}."
        ) from None
    if address.startswith("tls://") and not isinstance(args.get("ssl_context"), ssl.SSLContext):
        given = (security.tls_ca_file, security.tls_client_cert)
        missing = [key for key, value in zip(TLS_KEYS[:2], given, strict=True) if not value]
        raise SchedulerError(
            f"--scheduler {address!r} is a TLS address, and Dask's TLS settings for a client "
            f"are not given ({' and '.join(missing)} not set): give the CA certificate that "
            "signed the scheduler's certificate and this client's certificate and key. "
            f"{how}. Or give the scheduler's tcp:// address if it has one."
        )
    return args


def _probe(address: str, timeout: float) -> None:
    """Return once the scheduler at ``address`` answers, within ``timeout`` seconds in all.

    Why: ``Client(address, timeout=…)`` bounds only the TCP connect; Dask's handshake then
    reads the first reply without a bound, so a port that accepts the connection and never
    answers (a proxy, a service that is not Dask, a hung scheduler) held ``rti-rig fit`` for
    ever, and its Ctrl-C left a half-built Client waiting 40 s in ``__del__``. No Client is
    built before this answers. The host name is looked up first, with the whole ``timeout``
    (a slow resolver is not a missing name), and the connection has what is left."""
    args = _tls_settings(address)

    async def bounded() -> Any:
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout
        host_port = _host_port(address)
        ips = await _resolve(*host_port, timeout) if host_port is not None else []
        left = max(deadline - loop.time(), 0.0)
        return await asyncio.wait_for(_identity(address, timeout, args, ips), left)

    try:
        identity = _run_quietly(bounded())
    except TimeoutError:  # asyncio's is the builtin's since 3.11; Dask's own names the address
        raise _unreachable_scheduler(
            address,
            f"no Dask scheduler answered within {timeout:.0f} s: nothing listens there, a "
            "firewall drops the connection, or what accepts it is not a Dask scheduler",
        ) from None
    except _Refused as refused:
        raise _unreachable_scheduler(
            address, f"connection refused: no scheduler listens at {refused}"
        ) from None
    except _Unresolved as unresolved:
        host, why = unresolved.args
        raise SchedulerError(
            f"--scheduler {address!r} names the host {host!r}, which does not resolve ({why}): "
            "check the host name, or give the address `dask scheduler` prints, such as "
            "tcp://192.0.2.10:8786"
        ) from None
    except _LookupFailed as failed:
        host, why = failed.args
        raise SchedulerError(
            f"--scheduler {address!r}: the host {host!r} could not be looked up ({why}): "
            "check this machine's network and name servers (/etc/resolv.conf), or give the "
            "scheduler's IP address, such as tcp://192.0.2.10:8786"
        ) from None
    except Exception as exc:  # reset, a TLS failure, a reply that is not Dask's
        raise _unreachable_scheduler(address, f"{type(exc).__name__}: {exc}") from None
    if not (isinstance(identity, dict) and "workers" in identity):
        # e.g. a worker's or nanny's address: it answers, then the Client built on it failed
        # with a TypeError and hung 40 s in its __del__, printing a traceback
        what = identity.get("type", "server") if isinstance(identity, dict) else "server"
        raise SchedulerError(
            f"--scheduler {address!r} answers as a Dask {what}, not a scheduler: give the "
            "address `dask scheduler` prints (the one its workers were started with), such as "
            "tcp://HOST:8786"
        )


@contextmanager
def scheduler_client(address: str) -> Iterator[Any]:
    """A ``distributed.Client`` connected to ``address`` (closed afterwards), or None for
    :data:`THREADS`. Refuses clearly when the scheduler does not answer within
    :data:`CONNECT_TIMEOUT_S` or has no workers within :data:`WORKERS_TIMEOUT_S`."""
    if address == THREADS:
        yield None
        return
    from distributed import Client

    if _checked_address(address) != "inproc":  # one only in this process: nothing can hang
        _probe(address, CONNECT_TIMEOUT_S)
    try:
        client = Client(address, timeout=CONNECT_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError, ValueError, TypeError) as exc:
        raise _unreachable_scheduler(address, f"{type(exc).__name__}: {exc}") from None
    try:
        try:
            client.wait_for_workers(1, timeout=WORKERS_TIMEOUT_S)
        except (TimeoutError, OSError):
            raise SchedulerError(
                f"the Dask scheduler at {address!r} has no workers after "
                f"{WORKERS_TIMEOUT_S:.0f} s: start some with `dask worker {address}`; "
                f"{SHARED_PATHS}."
            ) from None
        yield client
    finally:
        _close_quietly(client)


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


def dask_bands(client: Any, address: str, source: Path) -> BandRunner:
    """A band runner for :func:`rti_rig.app.usecases.fit.run_fit`: the bands of ``source`` as
    chunks of a lazily read ``dask.array``, each fitted by :func:`fit_band` — in threads here
    (``client`` None) or on the cluster behind ``client``."""

    def run(
        stack: ImageStack, plan: BandPlan, tiles: list[slice]
    ) -> Iterator[tuple[slice, BandFit]]:
        import dask

        _, _, paths, _ = acquisition_files(source)
        array = lazy_stack(StackSource.of(paths, stack, read_image), plan.tile_rows)
        blocks = array.to_delayed().ravel()  # one per band, in row order
        if len(blocks) != len(tiles):
            raise AssertionError(f"{len(blocks)} chunks for {len(tiles)} bands")
        if client is None:
            tasks = [dask.delayed(fit_band, pure=True)(b, plan) for b in blocks]
            yield from _in_threads(tasks, tiles)
        else:
            threads = blas_threads()
            tasks = [dask.delayed(fit_band_recording, pure=True)(b, plan, threads) for b in blocks]
            yield from _on_cluster(client, address, tasks, tiles)

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
    client: Any, address: str, tasks: list[Any], tiles: list[slice]
) -> Iterator[tuple[slice, BandFit]]:
    """Band fits computed on the cluster, a bounded number in flight, yielded as they finish."""
    from distributed import as_completed

    threads = max(1, sum(client.nthreads().values()))
    window = BANDS_IN_FLIGHT_PER_THREAD * threads
    pending = iter(range(len(tasks)))
    outstanding: dict[Any, tuple[Any, int]] = {}

    def submit_next(watch: _GatherWatch) -> Any:
        i = next(pending, None)
        if i is None:
            return None
        future = watch.track(client.compute(tasks[i]))
        outstanding[future.key] = (future, i)
        return future

    with _gathers_watched(client) as watch:
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
                    raise _band_failed(client, address, exc) from None
                yield tiles[outstanding.pop(future.key)[1]], fitted
                future.release()
                following = submit_next(watch)
                if following is not None:
                    running.add(following)
        finally:  # the caller stopped early or failed: cancel what is left
            running.clear()
            if outstanding:
                client.cancel([f for f, _ in outstanding.values()])


def _band_failed(client: Any, address: str, exc: BaseException) -> SchedulerError:
    """The error of a band whose future failed (a lost scheduler, or a result that could not
    be fetched, said as such)."""
    if getattr(exc, "reason", None) == GATHER_FAILED:
        kept = "nothing of this fit was kept in --out"
        return SchedulerError(_unreachable(address, "a band of the fit", kept))
    if scheduler_lost(client, exc):
        return SchedulerError(
            f"lost the Dask scheduler at {address!r} while fitting (it stopped or the network "
            "to it failed); nothing of this fit was kept in --out: start the scheduler again "
            f"(`dask scheduler`, workers with `dask worker {address}`) and run the same command"
        )
    return SchedulerError(
        f"a band of the fit failed on the Dask cluster at {address!r}: "
        f"{type(exc).__name__}: {exc}. Check the workers' logs (memory limit?) and run again; "
        "finished outputs are not kept for a single-session fit"
    )


def run_fit_dask(req: FitRequest, scheduler: str = THREADS) -> FitResult:
    """:func:`run_fit` with its bands computed by Dask (``scheduler``: :data:`THREADS` or a
    scheduler address)."""
    with scheduler_client(scheduler) as client:
        return run_fit(req, bands=dask_bands(client, scheduler, req.source))


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
            f": {source} does not exist on worker host {socket.gethostname()}: {SHARED_PATHS}",
        )
    with _SESSION_LOCK, threadpool_limits(limits=threads, user_api="blas"):
        return fit_one(source, root, template)


def _batch_lost(
    scheduler: str, sources: list[Path], given: list[tuple[Path, Path]], root: Path
) -> SchedulerError:
    """The error of a batch whose scheduler went away: which sessions are finished in
    ``root`` (a session can finish on its worker while the client waits for another's result,
    so it is told by its folder, not by its future, which Dask cancels with the rest)."""
    finished = [g for s, g in given if batch_out_dir(root, s).exists()]
    kept = (
        f"{len(finished)} of {len(sources)} sessions are finished in {root} "
        f"({', '.join(map(str, finished))}) and are kept"
        if finished
        else f"no session is finished in {root} yet"
    )
    return SchedulerError(
        f"lost the Dask scheduler at {scheduler!r} during the batch (it stopped or the network "
        f"to it failed): {kept}. Start the scheduler again (`dask scheduler`, workers with "
        f"`dask worker {scheduler}`) and run the same command to fit the rest: finished "
        "sessions are skipped, partial ones redone"
    )


def run_batch_dask(
    sources: list[Path], root: Path, template: FitRequest, scheduler: str = THREADS
) -> list[BatchItem]:
    """A resumable batch (see :func:`rti_rig.app.usecases.fit_batch.run_batch`) on Dask: with
    :data:`THREADS`, sessions one after another with their bands in threads; on a cluster,
    every unfinished session a task of its own (run in parallel across the workers)."""
    if scheduler == THREADS:
        plan_batch(sources, root)
        return [fit_one(s, root, template, bands=dask_bands(None, THREADS, s)) for s in sources]
    # Absolute, as workers do not share this process's working directory, but not resolved:
    # ``resolve()`` followed a symlinked session folder, so its output was named after the
    # link's target (OUT/s1 for sess/coin_day2 -> s1, OUT/coin_day2 without Dask, so a rerun
    # either way fitted it again), and two spellings of one session (sess/s1, ./sess/s1) were
    # merged into one fit silently where the batch without Dask refuses them.
    given = list(zip([Path(os.path.abspath(s)) for s in sources], sources, strict=True))
    sources = [a for a, _ in given]
    root = root.resolve()
    with scheduler_client(scheduler) as client:
        todo = set(plan_batch(sources, root))  # refuses a source given twice, as without Dask
        threads = blas_threads()
        # A source missing here too is the user's typo, not the workers' filesystem: it is
        # refused here in the words of the batch without Dask ("does not exist: give a session
        # folder or an .lp file"); it had been sent and blamed on the workers' shared paths.
        with _gathers_watched(client) as watch:
            futures = {
                s: watch.track(client.submit(_fit_one_task, s, root, template, threads, pure=False))
                for s in todo
                if s.exists()
            }
            items = _batch_results(client, scheduler, sources, given, root, template, todo, futures)
        return [replace(item, source=g) for item, (_, g) in zip(items, given, strict=True)]


def _batch_results(
    client: Any,
    scheduler: str,
    sources: list[Path],
    given: list[tuple[Path, Path]],
    root: Path,
    template: FitRequest,
    todo: set[Path],
    futures: dict[Path, Any],
) -> list[BatchItem]:
    """Each session's item of a batch on a cluster, in the order given, as its task ends."""
    items = []
    for s in sources:
        if s in todo and s not in futures:
            items.append(fit_one(s, root, template))  # fails at once, naming the path
            continue
        if s not in futures:
            out = batch_out_dir(root, s)
            items.append(BatchItem(s, out, Outcome.SKIPPED, earlier_fit(out, s).skip_detail))
            continue
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
            if scheduler_lost(client, exc):
                raise _batch_lost(scheduler, sources, given, root) from None
            detail = f" on the Dask cluster: {type(exc).__name__}: {exc}"
            items.append(BatchItem(s, batch_out_dir(root, s), Outcome.FAILED, detail))
    return items
