"""`rti-rig fit --scheduler HOST:PORT` where the resolver is slow, silent or failing: a name is
said not to resolve only when the resolver says so.

The lookup had been cut at a fifth of the connect timeout (4 s of 20), under glibc's 5 s per
nameserver, so a machine whose first nameserver was down was told that a valid host "does not
resolve (the resolver gave no answer within 4 s)"; a resolver that failed for a reason of its
own (EAI_AGAIN, "Temporary failure in name resolution") was told the same. In-process, no
network: ``socket.getaddrinfo`` is replaced for one name under ``.test`` (RFC 6761), answered
with the loopback address.
"""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from rti_rig.app.usecases import fit_dask
from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
#: The scheduler's host name, looked up by the stand-in resolver only (RFC 6761: ``.test``).
HOST = "scheduler.rti-rig.test"
#: A slow answer: a glibc resolver whose first nameserver is down answers after its 5 s
#: per-server timeout; above the 4 s (a fifth of the 20 s default) the lookup had been cut at.
SLOW_S = 5.0
REAL_GETADDRINFO = socket.getaddrinfo
NOT_RESOLVED = "which does not resolve"


def _resolver(monkeypatch: pytest.MonkeyPatch, answer: Callable[[Any], list[Any]]) -> list[str]:
    """Look :data:`HOST` up with ``answer(port)`` (every other name as before); the hosts
    asked for, in order."""
    asked: list[str] = []

    def getaddrinfo(host: Any, port: Any, *args: Any, **kwargs: Any) -> list[Any]:
        if host != HOST:
            return REAL_GETADDRINFO(host, port, *args, **kwargs)
        asked.append(host)
        return answer(port)

    monkeypatch.setattr(socket, "getaddrinfo", getaddrinfo)
    return asked


def _loopback(port: Any) -> list[Any]:
    return REAL_GETADDRINFO("127.0.0.1", port, type=socket.SOCK_STREAM)


def _fit(tmp_path: Path, address: str) -> str:
    out = tmp_path / "fit"
    r = CliRunner().invoke(
        app, ["fit", str(ACQ), "--out", str(out), "--scheduler", address, "--no-qa"]
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "Traceback" not in said and not out.exists(), said
    return said


def test_a_slow_answer_is_not_a_host_that_does_not_resolve(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, closed_port: int
) -> None:
    def slow(port: Any) -> list[Any]:
        time.sleep(SLOW_S)  # in the stand-in resolver only: its answer comes late
        return _loopback(port)

    asked = _resolver(monkeypatch, slow)
    said = _fit(tmp_path, f"tcp://{HOST}:{closed_port}")
    assert NOT_RESOLVED not in said and "could not be looked up" not in said, said
    # the name answered: what is wrong is the port, found by connecting to the address given
    assert f"connection refused: no scheduler listens at {HOST}:{closed_port}" in said, said
    assert asked == [HOST], asked  # looked up once: a second slow lookup is not waited for


def test_a_name_the_resolver_does_not_know_is_said_not_to_resolve(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def unknown(port: Any) -> list[Any]:
        raise socket.gaierror(socket.EAI_NONAME, "Name or service not known")

    _resolver(monkeypatch, unknown)
    said = _fit(tmp_path, f"tcp://{HOST}:8786")
    assert (
        f"names the host '{HOST}', which does not resolve (Name or service not known): "
        "check the host name" in said
    ), said


def test_a_failing_resolver_is_not_a_host_that_does_not_resolve(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def failing(port: Any) -> list[Any]:
        raise socket.gaierror(socket.EAI_AGAIN, "Temporary failure in name resolution")

    _resolver(monkeypatch, failing)
    said = _fit(tmp_path, f"tcp://{HOST}:8786")
    assert NOT_RESOLVED not in said, said
    assert (
        f"the host '{HOST}' could not be looked up (Temporary failure in name resolution): "
        "check this machine's network and name servers" in said
    ), said


def test_a_silent_resolver_is_said_as_one_that_did_not_answer(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    released = threading.Event()

    def silent(port: Any) -> list[Any]:
        released.wait(120)  # until the test ends: the lookup thread is a daemon's
        raise socket.gaierror(socket.EAI_AGAIN, "Temporary failure in name resolution")

    _resolver(monkeypatch, silent)
    monkeypatch.setattr(fit_dask, "CONNECT_TIMEOUT_S", 3.0)
    try:
        said = _fit(tmp_path, f"tcp://{HOST}:8786")
    finally:
        released.set()
    assert NOT_RESOLVED not in said, said
    assert (
        f"the host '{HOST}' could not be looked up (the resolver did not answer within 3 s)" in said
    ), said


def test_the_scheduler_is_reached_at_the_address_looked_up_not_by_its_name_again(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A resolver that answers the scheduler's name once, then fails (EAI_AGAIN): the fit
    reaches the scheduler that is there. Dask's connect had looked the name up again after the
    probe's lookup, retrying the failing resolver for its whole connect timeout (23 lookups),
    and the scheduler was told as "no Dask scheduler answered"; a slow resolver cost its delay
    twice. The scheduler here has no workers: "has no workers" is said only once the Client
    is connected."""
    from distributed import LocalCluster

    answered: list[str] = []

    def getaddrinfo(host: Any, port: Any, *args: Any, **kwargs: Any) -> list[Any]:
        if host != HOST:
            return REAL_GETADDRINFO(host, port, *args, **kwargs)
        flags = kwargs.get("flags", args[3] if len(args) > 3 else 0)
        if flags & socket.AI_NUMERICHOST:  # as the C library answers a name asked so
            raise socket.gaierror(socket.EAI_NONAME, "Name or service not known")
        answered.append(host)
        if len(answered) > 1:
            raise socket.gaierror(socket.EAI_AGAIN, "Temporary failure in name resolution")
        return _loopback(port)

    monkeypatch.setattr(socket, "getaddrinfo", getaddrinfo)
    monkeypatch.setattr(fit_dask, "CONNECT_TIMEOUT_S", 10.0)
    monkeypatch.setattr(fit_dask, "WORKERS_TIMEOUT_S", 1.0)
    with LocalCluster(
        n_workers=0, processes=False, dashboard_address=None, protocol="tcp://", host="127.0.0.1"
    ) as cluster:
        port = cluster.scheduler_address.rsplit(":", 1)[1]
        said = _fit(tmp_path, f"tcp://{HOST}:{port}")
    assert f"the Dask scheduler at 'tcp://{HOST}:{port}' has no workers" in said, said
    assert f"dask worker tcp://{HOST}:{port}" in said, said  # the address given, in advice
    assert "no Dask scheduler answered" not in said and "could not be looked up" not in said
    assert answered == [HOST], answered  # looked up once: by the probe
