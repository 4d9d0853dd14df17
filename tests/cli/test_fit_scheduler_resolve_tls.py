"""`rti-rig fit --scheduler` with a host that does not resolve, or a tls:// / wss:// address:
said at once and in words, no network needed.

A mistyped host name waited the full 20 s (Dask retries a failed lookup until its connect
timeout) and was told as "no Dask scheduler answered"; a refused tls:// or wss:// port waited
the 20 s too (the bare connect that finds a refused tcp:// port at once was not used for
them); a tls:// address without Dask's TLS settings was told as "cannot reach the Dask
scheduler (TypeError: TLS expects a `ssl_context` …)" with advice to start a scheduler.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
#: A throwaway self-signed certificate and key (see its README): Dask's TLS settings load.
TLS = REPO / "tests" / "data" / "tls"
#: ``rti-rig`` waiting far longer for the scheduler than :data:`BOUND_S`: it ends within the
#: bound only if it does not wait for the timeout.
RTI_RIG_LONG_WAIT = [
    sys.executable,
    "-c",
    "from rti_rig.app.usecases import fit_dask; "
    "fit_dask.CONNECT_TIMEOUT_S = 3600.0; "
    "from rti_rig.cli import main; main()",
]
#: Far above importing Dask (and a resolver's own timeouts) on a loaded machine.
BOUND_S = 150
#: RFC 6761: a name under .invalid never resolves, whatever the resolver (or none).
NO_SUCH_HOST = "no-such-host.invalid"


def _env(tls: bool) -> dict[str, str]:
    """This environment without any Dask settings of the user's, with the test certificate
    as Dask's client TLS settings when ``tls``."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("DASK_")}
    env["DASK_CONFIG"] = str(REPO / "tests" / "data" / "tls" / "no-dask-config")
    if tls:
        env["DASK_DISTRIBUTED__COMM__TLS__CA_FILE"] = str(TLS / "cert.pem")
        env["DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT"] = str(TLS / "cert.pem")
        env["DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY"] = str(TLS / "key.pem")
    return env


def _fit(scheduler: str, out: Path, *, tls: bool) -> str:
    """stdout and stderr of ``rti-rig fit ACQ --out OUT --scheduler SCHEDULER --no-qa``, which
    must exit 2 without a traceback within :data:`BOUND_S` and leave no ``out``."""
    args = [*RTI_RIG_LONG_WAIT, "fit", str(ACQ), "--out", str(out)]
    args += ["--scheduler", scheduler, "--no-qa"]
    try:
        r = subprocess.run(args, capture_output=True, text=True, timeout=BOUND_S, env=_env(tls))
    except subprocess.TimeoutExpired as exc:
        pytest.fail(f"--scheduler {scheduler} still running after {BOUND_S} s: {exc.stderr!r}")
    text = r.stdout + r.stderr
    assert r.returncode == 2, text
    assert "Traceback" not in text and "Exception ignored" not in text, text
    assert not out.exists(), text
    return text


@pytest.mark.parametrize("scheme", ["tcp", "tls"])
def test_a_host_that_does_not_resolve_is_said_at_once(tmp_path: Path, scheme: str) -> None:
    address = f"{scheme}://{NO_SUCH_HOST}:8786"
    text = _fit(address, tmp_path / "fit", tls=True)
    assert f"--scheduler '{address}' names the host '{NO_SUCH_HOST}', which does not " in text
    assert "resolve" in text and "check the host name" in text, text
    assert "Timed out" not in text and "no Dask scheduler answered" not in text, text


@pytest.mark.parametrize("scheme", ["tls", "wss"])
def test_a_refused_tls_port_is_said_at_once(tmp_path: Path, closed_port: int, scheme: str) -> None:
    address = f"{scheme}://127.0.0.1:{closed_port}"
    text = _fit(address, tmp_path / "fit", tls=True)
    assert f"cannot reach the Dask scheduler at '{address}'" in text, text
    assert f"connection refused: no scheduler listens at 127.0.0.1:{closed_port}" in text, text
    assert "Timed out" not in text, text


def test_a_tls_address_without_tls_settings_says_what_is_missing(
    tmp_path: Path, closed_port: int
) -> None:
    address = f"tls://127.0.0.1:{closed_port}"
    text = _fit(address, tmp_path / "fit", tls=False)
    assert f"--scheduler '{address}' is a TLS address" in text, text
    assert "distributed.comm.tls.ca-file and distributed.comm.tls.client.cert not set" in text
    assert "DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT" in text and "~/.config/dask/" in text
    assert "cannot reach" not in text and "ssl_context" not in text, text


def test_tls_settings_that_cannot_be_loaded_name_the_files(tmp_path: Path) -> None:
    env_given = _env(tls=True)
    missing = tmp_path / "no-such-ca.pem"
    env_given["DASK_DISTRIBUTED__COMM__TLS__CA_FILE"] = str(missing)
    args = [*RTI_RIG_LONG_WAIT, "fit", str(ACQ), "--out", str(tmp_path / "fit")]
    args += ["--scheduler", "tls://127.0.0.1:1", "--no-qa"]
    r = subprocess.run(args, capture_output=True, text=True, timeout=BOUND_S, env=env_given)
    text = r.stdout + r.stderr
    assert r.returncode == 2 and "Traceback" not in text, text
    assert "Dask's TLS settings cannot be used" in text, text
    assert f"distributed.comm.tls.ca-file = '{missing}'" in text, text
    assert not (tmp_path / "fit").exists()


@pytest.mark.parametrize("tls", [False, True])
def test_required_encryption_with_a_tcp_address_says_to_use_tls(
    tmp_path: Path, closed_port: int, tls: bool
) -> None:
    """``distributed.comm.require-encryption`` set and a tcp:// address: Dask refuses the
    unencrypted transport before connecting. That had been told as "cannot reach the Dask
    scheduler (RuntimeError: encryption required …)" with advice to start a scheduler; the
    config's requirement is said, with the tls:// address and the TLS keys to give (with or
    without them set: a tcp:// address is refused either way)."""
    env = _env(tls)
    env["DASK_DISTRIBUTED__COMM__REQUIRE_ENCRYPTION"] = "True"
    address = f"tcp://127.0.0.1:{closed_port}"
    args = [*RTI_RIG_LONG_WAIT, "fit", str(ACQ), "--out", str(tmp_path / "fit")]
    args += ["--scheduler", address, "--no-qa"]
    r = subprocess.run(args, capture_output=True, text=True, timeout=BOUND_S, env=env)
    text = " ".join((r.stdout + r.stderr).split())
    assert r.returncode == 2 and "Traceback" not in text, text
    assert f"--scheduler '{address}': Dask's configuration requires encryption" in text, text
    assert "distributed.comm.require-encryption = True" in text, text
    assert "Give the scheduler's tls:// address" in text, text
    assert "distributed.comm.tls.ca-file, distributed.comm.tls.client.cert" in text, text
    assert "DASK_DISTRIBUTED__COMM__REQUIRE_ENCRYPTION" in text, text
    assert "cannot reach" not in text and "connection refused" not in text, text
    assert not (tmp_path / "fit").exists()
