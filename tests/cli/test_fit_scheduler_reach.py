"""`rti-rig fit --scheduler` reaching a real in-process scheduler: over tls:// by a host name,
with Dask's TLS settings from its configuration or from its security loader, and past a first
address that cannot be reached.

Since the Dask client was given the ``Security`` that presents the name the user gave, Dask no
longer called its ``distributed.client.security-loader`` (its Client calls it only when given
no ``security``): a tls:// address set up by a loader was told that Dask's TLS settings are not
given. And a name whose first address could not be reached otherwise than refused (no route, a
firewall that drops the connection) ended the probe's search: the client fell back to the
name, which Dask looked up again. In-process, no network: the resolver is replaced for one name
under ``.test`` (RFC 6761), and the certificate is the throwaway one in tests/data/tls.
"""

from __future__ import annotations

import asyncio
import errno
import socket
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import dask.config
import pytest
from typer.testing import CliRunner

from rti_rig.app.usecases import fit_dask, scheduler_probe
from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
#: A throwaway self-signed certificate and key (see its README), its own CA.
CERT, KEY = (str(REPO / "tests" / "data" / "tls" / name) for name in ("cert.pem", "key.pem"))
#: Dask's client TLS settings from its configuration.
TLS_CONFIG = {
    "distributed.comm.tls.ca-file": CERT,
    "distributed.comm.tls.client.cert": CERT,
    "distributed.comm.tls.client.key": KEY,
}
NO_TLS_CONFIG = dict.fromkeys(TLS_CONFIG)
#: The scheduler's host name, looked up by the stand-in resolver only (RFC 6761: ``.test``).
HOST = "scheduler.rti-rig.test"
#: RFC 5737 TEST-NET-1: routed nowhere; its connection is made to fail here, not sent.
DEAD = "192.0.2.1"
REAL_GETADDRINFO = socket.getaddrinfo
REAL_OPEN_CONNECTION = asyncio.open_connection

LOADER = '''
calls = []


def load(info):
    """Dask's security loader: records what it is called with, gives the test's TLS settings."""
    from distributed.security import Security

    calls.append(dict(info))
    return Security(tls_ca_file={cert!r}, tls_client_cert={cert!r}, tls_client_key={key!r})
'''


def _fit(tmp_path: Path, address: str) -> Path:
    """The fit's output folder, once ``rti-rig fit ACQ --scheduler ADDRESS`` has written it."""
    out = tmp_path / "fit"
    r = CliRunner().invoke(
        app, ["fit", str(ACQ), "--out", str(out), "--scheduler", address, "--no-qa"]
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "Traceback" not in said, said
    assert (out / "normals.npy").is_file() and (out / "fit.json").is_file(), said
    return out


@pytest.fixture
def tls_scheduler() -> Iterator[int]:
    """The port of an in-process tls:// scheduler on 127.0.0.1 with one worker (threads)."""
    from distributed import LocalCluster
    from distributed.security import Security

    security = Security(
        tls_ca_file=CERT,
        tls_scheduler_cert=CERT,
        tls_scheduler_key=KEY,
        tls_worker_cert=CERT,
        tls_worker_key=KEY,
        tls_client_cert=CERT,
        tls_client_key=KEY,
        require_encryption=True,
    )
    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        dashboard_address=None,
        protocol="tls://",
        host="127.0.0.1",
        security=security,
    ) as cluster:
        yield int(cluster.scheduler_address.rsplit(":", 1)[1])


def test_a_tls_scheduler_is_fitted_on_by_its_host_name(tmp_path: Path, tls_scheduler: int) -> None:
    """tls://localhost: the name is presented, the address that accepted is connected to (the
    certificate's name, rti-rig-test, is not localhost: Dask checks only its CA)."""
    with dask.config.set(TLS_CONFIG):
        _fit(tmp_path, f"tls://localhost:{tls_scheduler}")


def test_dask_s_security_loader_gives_the_tls_settings_called_with_the_address_given(
    tmp_path: Path, tls_scheduler: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The loader is called once, with the name the user gave, and its settings are used by
    the probe and by the client: none are in Dask's configuration."""
    module = "rti_rig_test_security_loader"
    (tmp_path / f"{module}.py").write_text(LOADER.format(cert=CERT, key=KEY))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, module, raising=False)
    address = f"tls://localhost:{tls_scheduler}"
    with dask.config.set({**NO_TLS_CONFIG, scheduler_probe.SECURITY_LOADER: f"{module}.load"}):
        _fit(tmp_path, address)
    assert sys.modules[module].calls == [{"address": address}]


@pytest.mark.parametrize("dead", ["unreachable", "blackholed"])
def test_a_first_address_that_cannot_be_reached_is_passed_over_for_the_next(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, dead: str
) -> None:
    """The name resolves to a dead address, then to the scheduler's; the resolver answers
    once only, then fails (EAI_AGAIN), so a client that fell back to the name fails to look it
    up for its whole connect timeout. "unreachable": the connection fails at once with no
    route to the host; "blackholed": it never answers."""
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
        return [
            *REAL_GETADDRINFO(DEAD, port, type=socket.SOCK_STREAM),
            *REAL_GETADDRINFO("127.0.0.1", port, type=socket.SOCK_STREAM),
        ]

    tried: list[str] = []

    async def open_connection(host: Any, *args: Any, **kwargs: Any) -> Any:
        tried.append(host)
        if host != DEAD:
            return await REAL_OPEN_CONNECTION(host, *args, **kwargs)
        if dead == "unreachable":
            raise OSError(errno.EHOSTUNREACH, "No route to host")
        await asyncio.Event().wait()  # never set: a dropped SYN, until the probe's limit

    monkeypatch.setattr(socket, "getaddrinfo", getaddrinfo)
    monkeypatch.setattr(asyncio, "open_connection", open_connection)
    monkeypatch.setattr(fit_dask, "CONNECT_TIMEOUT_S", 20.0)
    with (
        dask.config.set(NO_TLS_CONFIG),
        LocalCluster(
            n_workers=1,
            threads_per_worker=1,
            processes=False,
            dashboard_address=None,
            protocol="tcp://",
            host="127.0.0.1",
        ) as cluster,
    ):
        port = cluster.scheduler_address.rsplit(":", 1)[1]
        _fit(tmp_path, f"tcp://{HOST}:{port}")
    assert tried[:2] == [DEAD, "127.0.0.1"], tried
    assert answered == [HOST], answered  # looked up once: by the probe


@pytest.mark.parametrize(
    ("term", "said"),
    [
        ("rti_rig_no_such_module.load", "Dask's security loader cannot be imported"),
        ("builtins.setattr", "Dask's security loader 'builtins.setattr' failed (TypeError"),
        ("builtins.len", "Dask's security loader 'builtins.len' returned int, not a"),
    ],
)
def test_a_security_loader_that_cannot_be_used_is_said_naming_the_key(
    tmp_path: Path, term: str, said: str
) -> None:
    """Said before anything is connected to, exit 2, no traceback."""
    out = tmp_path / "fit"
    with dask.config.set({scheduler_probe.SECURITY_LOADER: term}):
        r = CliRunner().invoke(
            app, ["fit", str(ACQ), "--out", str(out), "--scheduler", "tls://127.0.0.1:1"]
        )
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert said in text and "distributed.client.security-loader" in text, text
    assert "Traceback" not in text and not out.exists(), text
