"""`rti-rig fit --scheduler` reaching a real in-process scheduler over tls:// by a host name,
with Dask's TLS settings from its configuration or from its security loader.

Since the Dask client was given the ``Security`` that presents the name the user gave, Dask no
longer called its ``distributed.client.security-loader`` (its Client calls it only when given
no ``security``): a tls:// address set up by a loader was told that Dask's TLS settings are not
given. In-process, no network: the certificate is the throwaway one in tests/data/tls.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import dask.config
import pytest
from typer.testing import CliRunner

from rti_rig.app.usecases import scheduler_probe
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
