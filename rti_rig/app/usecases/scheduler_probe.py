"""Whether ``rti-rig fit --scheduler ADDRESS`` can use that Dask scheduler, found before any
``distributed.Client`` is built: the address parsed and its transport usable here, the host
looked up, Dask's TLS settings loaded, and one bounded connection that asks the scheduler who
it is.

Why its own module: these checks are about reaching a scheduler, not about fitting; they had
grown to half of :mod:`rti_rig.app.usecases.fit_dask`, which builds the client on them and
runs the fit. Dask is imported only inside the functions (this module is imported only when
``--scheduler`` is given).
"""

from __future__ import annotations

import asyncio
import copy
import gc
import signal
import socket
import threading
from collections.abc import Callable, Coroutine, Sequence
from contextlib import suppress
from dataclasses import dataclass, replace
from typing import Any

from rti_rig.core.errors import RtiRigError

#: ``--scheduler`` value for Dask's threaded scheduler in this process.
THREADS = "threads"

SHARED_PATHS = (
    "every Dask worker must see the session's files at the same paths as this machine "
    "(a shared filesystem mounted at the same place)"
)


class SchedulerError(RtiRigError):
    """The Dask scheduler cannot be used: unreachable, no workers, or workers that cannot read
    the images."""


def unreachable_scheduler(address: str, why: str) -> SchedulerError:
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


def checked_address(address: str) -> str:
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
) -> tuple[Any, Reached]:
    """A Dask comm to ``address``, its handshake done (``distributed.comm.connect``), after
    plain connections to ``ips`` (its host's addresses, looked up before: see :func:`probe`)
    find a refused port at once; and where it was made (:class:`Reached`).

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
    refuses (localhost's ::1 may refuse where 127.0.0.1 listens); an address that cannot be
    reached otherwise (no route, no answer) is passed over for the next. Dask's connect goes
    to the first address that accepted, for tcp:// and tls:// (see :class:`Reached`)."""
    from distributed.comm import connect, parse_address
    from distributed.comm.addressing import unparse_host_port

    scheme, location = parse_address(address)
    host_port = _host_port(address)
    reached = Reached(address)
    if host_port is not None and ips:
        host, port = host_port
        tls: Any = None
        if scheme == "tls":
            tls = connection_args.get("ssl_context")  # checked by _tls_settings: a context
        elif scheme == "wss":  # Dask's wss:// gives tornado None for its default context
            tls = connection_args.get("ssl_context") or True

        async def first_accepting(limit: float) -> tuple[bool, str | None]:
            """(every address refused, the first that accepted: None if none did), within
            ``limit`` seconds in all, each address given an equal share of what is left.

            Why: an address that fails otherwise than refused (no route to it, a firewall
            that drops the connection) had ended the search, and the client fell back to the
            name, which Dask looked up again (5–13 s with a slow resolver); one that never
            answered had taken the whole limit from the addresses after it."""
            loop = asyncio.get_running_loop()
            deadline = loop.time() + limit
            every_refused = True
            for n, ip in enumerate(ips):
                share = max(deadline - loop.time(), 0.0) / (len(ips) - n)
                try:
                    _, writer = await asyncio.wait_for(
                        asyncio.open_connection(
                            ip, port, ssl=tls, server_hostname=host if tls else None
                        ),
                        share,
                    )
                except TimeoutError:
                    every_refused = False
                    continue
                except (OSError, ValueError) as exc:
                    every_refused = every_refused and _refused(exc)
                    continue
                writer.close()
                return False, ip
            return every_refused, None

        every_refused, accepted = await first_accepting(timeout / 5)
        if every_refused:
            raise _Refused(location)
        if accepted is not None and scheme in ("tcp", "tls"):
            named = host if scheme == "tls" else None
            reached = Reached(f"{scheme}://{unparse_host_port(accepted, port)}", named)
            connection_args = reached.connection_args(connection_args)
    return await connect(reached.address, timeout=timeout, **connection_args), reached


async def _identity(
    address: str, timeout: float, connection_args: dict[str, Any], ips: Sequence[str] = ()
) -> tuple[Any, Reached, Any]:
    """The scheduler's answer to Dask's ``identity`` request (a connection, its handshake, one
    request and its reply), where it came from, and, from a scheduler, its answer to Dask's
    ``versions`` request (None from anything else); ``ips``: its host's addresses
    (:func:`_connect`)."""
    comm, reached = await _connect(address, timeout, connection_args, ips)
    try:
        await comm.write({"op": "identity", "reply": True})
        identity = await comm.read()
        versions = None
        if _is_scheduler(identity):
            await comm.write({"op": "versions", "reply": True})
            versions = await comm.read()
        return identity, reached, versions
    finally:
        comm.abort()


def _is_scheduler(identity: Any) -> bool:
    return isinstance(identity, dict) and "workers" in identity


def _other_dask(address: str, versions: Any) -> SchedulerError | None:
    """The refusal of a scheduler that runs another version of Dask's ``distributed`` than
    this machine (None when it runs this one, or does not say).

    Why: Dask's messages change between versions; a ``Client`` of one built on the scheduler
    of another failed as it connected ("TypeError: Scheduler.identity() got an unexpected
    keyword argument 'n_workers'"), which was told as a scheduler that "cannot be reached",
    with advice to start one, then hung 40 s in the Client's ``__del__`` and printed a
    traceback. Refused before any Client is built, naming both versions."""
    import distributed

    packages = versions.get("packages") if isinstance(versions, dict) else None
    theirs = packages.get("distributed") if isinstance(packages, dict) else None
    if not isinstance(theirs, str) or theirs == distributed.__version__:
        return None
    mine = distributed.__version__
    return SchedulerError(
        f"the Dask scheduler at {address!r} runs distributed {theirs}, and this machine "
        f"distributed {mine}: Dask's client, scheduler and workers must run the same version "
        f"(their messages differ between versions). Start the scheduler and its workers "
        f"from an environment with distributed {mine}, as this one (pip install "
        f"'distributed=={mine}'), and run the same command"
    )


def _run_quietly(make: Callable[[], Coroutine[Any, Any, Any]]) -> Any:
    """``asyncio.run(make())``, without asyncio's report of the tasks a stop leaves behind.

    Why: a Ctrl-C that lands while the probe connects cancels the connection's tasks, and one
    that ends with an exception of its own (a comm closed under it) was printed by
    ``asyncio.run``'s shutdown as "unhandled exception during asyncio.run() shutdown" with a
    traceback, after "Stopped (Ctrl-C)". And ``asyncio.run`` turns a Ctrl-C into a cancellation
    of its main task, which the connection under way could outlive: under load the stopped
    ``rti-rig fit`` then waited on the silent port for good (a test timed out at 150 s). Here
    the Ctrl-C is raised as it comes, and what it leaves is given one second to end.

    Why every coroutine is ended before the loop is closed: one left suspended (a task still
    pending after that second, or a coroutine the Ctrl-C cut through in the frame awaiting it,
    held by the stop's own traceback) was closed later by the garbage collector; closing its
    half-made connection on the closed loop printed "Exception ignored in: <coroutine object
    open_connection …> … Event loop is closed" under "Stopped (Ctrl-C)" (CI, once).

    Why the coroutine is made here, from ``make``, once the loop is, and closed at the end:
    made by the caller and passed in, a Ctrl-C landing before the loop had wrapped it in a
    task (while the loop was being made, or in ``run_until_complete``'s first lines) left it
    never started, and the stopped ``fit`` said "note: coroutine 'probe.<locals>.bounded' was
    never awaited" under "Stopped (Ctrl-C)". Closing a coroutine never started, or one already
    ended, does nothing else."""
    loop: asyncio.AbstractEventLoop | None = None
    main: Coroutine[Any, Any, Any] | None = None
    cut = False
    ctrl_c: list[bool] = []  # a Ctrl-C the loop took (_ctrl_c_stops)
    held = False
    try:
        loop = asyncio.new_event_loop()
        held = _ctrl_c_stops(loop, ctrl_c)
        main = make()
        try:
            result = loop.run_until_complete(main)
        except RuntimeError:  # "Event loop stopped before Future completed": the Ctrl-C's stop
            if not ctrl_c:
                raise
        if ctrl_c:  # raised here, in this frame, whatever the loop was running when it came
            raise KeyboardInterrupt
        return result
    except BaseException as exc:  # a stop, or an error the caller words: its frames let go
        exc.__traceback__ = None  # what is said never shows them; they hold the cut coroutines
        cut = True
        raise
    finally:
        if loop is not None:
            if held:  # Python's own Ctrl-C again for the clean-up (a second one cuts it short)
                with suppress(Exception):
                    loop.remove_signal_handler(signal.SIGINT)
            loop.set_exception_handler(lambda _loop, _context: None)
            try:
                _end_what_is_left(loop, cut)
            finally:
                if main is not None:  # never wrapped in a task, if the stop came first
                    with suppress(BaseException):
                        main.close()
                loop.close()


def _ctrl_c_stops(loop: asyncio.AbstractEventLoop, took: list[bool]) -> bool:
    """Whether a Ctrl-C now stops ``loop`` (noted in ``took``) instead of raising
    KeyboardInterrupt wherever Python happens to be: only where Python's own handler is in
    place (a caller that ignores SIGINT keeps ignoring it) and this is the main thread.

    Why: Python raises a Ctrl-C's KeyboardInterrupt in whatever frame runs when it comes, and
    one that came while the garbage collector ran a finalizer (a half-made connection's
    ``StreamWriter.__del__``) was printed as "Exception ignored in …" and lost: the stopped
    ``fit`` waited out the 20 s for the silent port and said it could not reach the scheduler
    (CI under load, once). The loop's own handler runs between its callbacks, never inside a
    finalizer; the stop is raised by :func:`_run_quietly` once the loop has returned."""
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        return False

    def stop() -> None:
        took.append(True)
        loop.stop()

    try:
        loop.add_signal_handler(signal.SIGINT, stop)
    except (ValueError, RuntimeError, NotImplementedError):  # not the main thread; no Unix
        return False
    return True


def _end_what_is_left(loop: asyncio.AbstractEventLoop, cut: bool) -> None:
    """The tasks left on ``loop`` cancelled and given one second, then any still pending and,
    if ``cut`` short by an exception, any coroutine no longer referenced, ended while ``loop``
    is open (:func:`_run_quietly`)."""
    left = [task for task in asyncio.all_tasks(loop) if not task.done()]
    for task in left:
        task.cancel()
    if left:  # bounded: a task that ignores its cancellation must not hold the stop
        loop.run_until_complete(asyncio.wait(left, timeout=1.0))
    for task in left:
        if not task.done():
            with suppress(BaseException):  # its own error on the way out is not the user's
                task.get_coro().close()
    if cut or left:  # the coroutines only the stop's frames held: closed now, on an open loop
        gc.collect()
    loop.run_until_complete(asyncio.sleep(0))  # what their ends scheduled (a transport's close)
    loop.run_until_complete(loop.shutdown_asyncgens())


@dataclass(frozen=True)
class Reached:
    """Where the probe reached the scheduler: the ``address`` Dask's ``Client`` is to connect
    to, and for a tls:// one the host name its TLS handshake must still present.

    Why: Dask's connect looks a host name up again, after the probe had resolved it: a slow
    resolver (a nameserver down, 5 s a lookup) cost its delay twice, and one that answered
    the probe, then failed, had Dask retry the lookup for the whole connect timeout and the
    scheduler, which was there, told as "no Dask scheduler answered within 20 s" (23
    lookups, measured). For tcp:// and tls:// the address is the given one with its host
    replaced by the address that accepted the probe's connection, so no lookup is made after
    the probe's; a tls:// connection still presents the host name given (``server_hostname``:
    sent as SNI only, for a proxy or server that picks its certificate by it; Dask never
    checks the certificate's name, its ``Security`` sets ``check_hostname = False`` and
    verifies only that the CA it is given signed the certificate). ws:// and wss:// keep the
    name (their URL, and the Host header a proxy routes by): Dask looks it up again there,
    within its connect timeout."""

    address: str
    #: the host name a tls:// connection to :attr:`address` presents; None: the name given
    server_hostname: str | None = None
    #: Dask's ``Security`` the probe connected with (:func:`dask_security`); None: not built
    base_security: Any = None

    def connection_args(self, args: dict[str, Any]) -> dict[str, Any]:
        """Dask's connection arguments ``args`` for a connection to :attr:`address`."""
        if self.server_hostname is None:
            return args
        return {**args, "server_hostname": self.server_hostname}

    def security(self) -> Any:
        """The ``security`` to build the ``Client`` with: :attr:`base_security` (None: Dask's
        own, its security loader or configuration, as without), and where a host name must be
        presented a copy of it that gives the name too (Dask's own ``Worker`` sets the same
        key for its scheduler's name).

        Why a copy of the probe's: a ``Client`` given any ``security`` does not call Dask's
        ``distributed.client.security-loader``; a ``Security()`` built here from Dask's
        configuration alone lost the loader's settings for every tls:// address."""
        base = self.base_security
        if self.server_hostname is None:
            return base
        if base is None:
            from distributed.security import Security

            base = Security()
        name = self.server_hostname

        class _Named(type(base)):  # type: ignore[misc]
            __slots__ = ()  # the base's layout: a copy of it can take this class

            def get_connection_args(self, role: str) -> dict[str, Any]:
                return {**super().get_connection_args(role), "server_hostname": name}

        named = copy.copy(base)  # every setting of the base's, whatever its class adds
        named.__class__ = _Named
        return named


#: Dask's configuration key naming a function that gives a client's ``Security``.
SECURITY_LOADER = "distributed.client.security-loader"


def dask_security(address: str) -> Any:
    """The ``Security`` Dask's ``Client`` builds for ``address`` when given none: the one the
    function configured as ``distributed.client.security-loader`` returns, called with the
    address as given (a dict, True: a temporary one, None: from Dask's configuration), else
    ``Security()``.

    Why: the probe and the Client must connect with the settings Dask itself would use, and
    the Client is now always given them (:meth:`Reached.security`), which stops Dask from
    calling the loader. A loader that cannot be imported or fails is said in words, naming
    the key, not a traceback."""
    import dask.config
    from distributed.security import Security
    from distributed.utils import import_term

    term = dask.config.get(SECURITY_LOADER, None)
    if not term:
        return Security()
    fix = f"Check Dask's configuration key {SECURITY_LOADER} (= {term!r})"
    try:
        loader = import_term(term)
    except Exception as exc:  # any failure to import it means the same: not usable
        raise SchedulerError(
            f"--scheduler {address!r}: Dask's security loader cannot be imported "
            f"({type(exc).__name__}: {exc}). {fix}: it names a function as module.function, "
            "in a module this Python can import."
        ) from None
    try:
        security = loader({"address": address})
        if security is None or security is False:
            return Security()
        if isinstance(security, dict):
            return Security(**security)
        if security is True:
            return Security.temporary()
    except Exception as exc:  # the loader's own code: whatever it raises is its failure
        raise SchedulerError(
            f"--scheduler {address!r}: Dask's security loader {term!r} failed "
            f"({type(exc).__name__}: {exc}). {fix} and the function it names."
        ) from None
    if not isinstance(security, Security):
        raise SchedulerError(
            f"--scheduler {address!r}: Dask's security loader {term!r} returned "
            f"{type(security).__name__}, not a distributed.Security, a dict of its settings, "
            f"True or None. {fix} and the function it names."
        )
    return security


#: Dask's configuration keys a tls:// client needs (its ``Security()`` reads them).
TLS_KEYS = (
    "distributed.comm.tls.ca-file",
    "distributed.comm.tls.client.cert",
    "distributed.comm.tls.client.key",
)


def _encrypted(scheme: str) -> bool:
    """Whether Dask's connector for ``scheme`` is encrypted, as Dask itself judges it before a
    connection under ``distributed.comm.require-encryption`` (its ``encrypted`` attribute:
    False for tcp://, True for tls://). A connector without the attribute (ws://, wss://) is
    not refused by Dask under that setting, and so not here either."""
    from distributed.comm.registry import get_backend

    return getattr(get_backend(scheme).get_connector(), "encrypted", None) is not False


def _tls_settings(address: str) -> tuple[Any, dict[str, Any]]:
    """Dask's ``Security`` for ``address`` (:func:`dask_security`) and the connection
    arguments the ``Client`` will use, refused in words when they cannot serve ``address``.

    Why: a tls:// address without TLS settings was told as "cannot reach the Dask scheduler
    (TypeError: TLS expects a `ssl_context` argument …)", with advice to start a scheduler,
    when what is missing is this client's certificate and the CA to check the scheduler's;
    and a certificate file that cannot be read raised out of here with a traceback. With
    ``distributed.comm.require-encryption`` set, a tcp:// address was told as "cannot reach
    the Dask scheduler (RuntimeError: encryption required by Dask configuration …)" with
    advice to start a scheduler: Dask refuses the unencrypted transport before connecting."""
    import ssl

    import dask.config
    from distributed.comm import parse_address

    how = (
        f"Dask reads them from its configuration: {', '.join(TLS_KEYS)} (the key may be in "
        "the certificate file), in a YAML file under ~/.config/dask/ or as the environment "
        "variables DASK_DISTRIBUTED__COMM__TLS__CA_FILE, "
        "DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT and DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY"
    )
    try:
        security = dask_security(address)
        args: dict[str, Any] = security.get_connection_args("client")
    except (OSError, ValueError) as exc:  # ssl.SSLError is an OSError
        given = {key: dask.config.get(key, None) for key in TLS_KEYS}
        named = ", ".join(f"{key} = {value!r}" for key, value in given.items() if value)
        raise SchedulerError(
            f"--scheduler {address!r}: Dask's TLS settings cannot be used "
            f"({type(exc).__name__}: {exc}; {named or 'none given'}). Check the files they "
            f"name; {how}."
        ) from None
    scheme, _ = parse_address(address)  # tcp:// where none is given, as Dask's own
    if args.get("require_encryption") and not _encrypted(scheme):
        raise SchedulerError(
            f"--scheduler {address!r}: Dask's configuration requires encryption "
            f"(distributed.comm.require-encryption = "
            f"{dask.config.get('distributed.comm.require-encryption', None)!r}), and Dask "
            f"refuses {scheme}://, which is not encrypted. Give the scheduler's tls:// address "
            "(a scheduler started with TLS, `dask scheduler --protocol tls` and its "
            "certificate options) with Dask's TLS settings for a client: the CA certificate "
            "that signed the scheduler's certificate and this client's certificate and key. "
            f"{how}. Or, for a scheduler without TLS, unset distributed.comm.require-encryption "
            "(the environment variable DASK_DISTRIBUTED__COMM__REQUIRE_ENCRYPTION)."
        )
    if address.startswith("tls://") and not isinstance(args.get("ssl_context"), ssl.SSLContext):
        given = (security.tls_ca_file, security.tls_client_cert)
        missing = [key for key, value in zip(TLS_KEYS[:2], given, strict=True) if not value]
        raise SchedulerError(
            f"--scheduler {address!r} is a TLS address, and Dask's TLS settings for a client "
            f"are not given ({' and '.join(missing)} not set): give the CA certificate that "
            "signed the scheduler's certificate and this client's certificate and key. "
            f"{how}. Or give the scheduler's tcp:// address if it has one."
        )
    return security, args


def probe(address: str, timeout: float) -> Reached:
    """Where the scheduler at ``address`` answered, once it has, within ``timeout`` seconds
    in all (the ``Client`` is to be built on it: :class:`Reached`).

    Why: ``Client(address, timeout=…)`` bounds only the TCP connect; Dask's handshake then
    reads the first reply without a bound, so a port that accepts the connection and never
    answers (a proxy, a service that is not Dask, a hung scheduler) held ``rti-rig fit`` for
    ever, and its Ctrl-C left a half-built Client waiting 40 s in ``__del__``. No Client is
    built before this answers. The host name is looked up first, with the whole ``timeout``
    (a slow resolver is not a missing name), and the connection has what is left."""
    security, args = _tls_settings(address)

    async def bounded() -> Any:
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout
        host_port = _host_port(address)
        ips = await _resolve(*host_port, timeout) if host_port is not None else []
        left = max(deadline - loop.time(), 0.0)
        return await asyncio.wait_for(_identity(address, timeout, args, ips), left)

    try:
        identity, reached, versions = _run_quietly(bounded)
    except TimeoutError:  # asyncio's is the builtin's since 3.11; Dask's own names the address
        raise unreachable_scheduler(
            address,
            f"no Dask scheduler answered within {timeout:.0f} s: nothing listens there, a "
            "firewall drops the connection, or what accepts it is not a Dask scheduler",
        ) from None
    except _Refused as refused:
        raise unreachable_scheduler(
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
    except (MemoryError, OverflowError):
        # Dask read another service's first bytes (an HTTP server's "HTTP/1.0 426 …") as the
        # length of its message and tried to make room for 3 EiB: the user had been shown
        # "MemoryError: Unable to allocate 3.01 EiB" and told to start a scheduler
        raise SchedulerError(
            f"--scheduler {address!r}: what answers there is not a Dask scheduler (its reply "
            "is not a Dask message: an HTTP or SSH server, a proxy, or another service on "
            "that port?): give the address `dask scheduler` prints, such as tcp://HOST:8786"
        ) from None
    except Exception as exc:  # reset, a TLS failure, a reply that is not Dask's
        raise unreachable_scheduler(address, f"{type(exc).__name__}: {exc}") from None
    if not _is_scheduler(identity):
        # e.g. a worker's or nanny's address: it answers, then the Client built on it failed
        # with a TypeError and hung 40 s in its __del__, printing a traceback
        what = identity.get("type", "server") if isinstance(identity, dict) else "server"
        raise SchedulerError(
            f"--scheduler {address!r} answers as a Dask {what}, not a scheduler: give the "
            "address `dask scheduler` prints (the one its workers were started with), such as "
            "tcp://HOST:8786"
        )
    other = _other_dask(address, versions)
    if other is not None:
        raise other
    return replace(reached, base_security=security)
