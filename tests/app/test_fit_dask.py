"""`rti-rig fit --scheduler threads` and the Dask runner: outputs byte-identical to the
single-process fit, the batch resumable, unreadable images on a worker refused clearly."""

from __future__ import annotations

import logging
import shutil
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from conftest import dead_pid
from typer.testing import CliRunner

from rti_rig.cli import app

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

runner = CliRunner()


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_session(tmp_path_factory.mktemp("dask") / "s", size=(72, 88))[0]


def same_files(a: Path, b: Path) -> list[str]:
    """Names of the files of ``a``; asserts ``b`` has the same files with the same bytes."""
    names = sorted(p.name for p in a.iterdir())
    assert names == sorted(p.name for p in b.iterdir())
    for name in names:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    return names


@pytest.mark.parametrize(
    "model", [pytest.param("auto", marks=pytest.mark.slow), "robust-ps", "ptm"]
)
def test_dask_threads_write_the_same_bytes_as_the_single_process_fit(
    session: Path, tmp_path: Path, model: str
) -> None:
    plain, threads = tmp_path / "plain", tmp_path / "threads"
    base = ["fit", str(session), "--model", model]
    r = runner.invoke(app, [*base, "--out", str(plain)])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, [*base, "--out", str(threads), "--scheduler", "threads"])
    assert r.exit_code == 0, r.output
    names = same_files(plain, threads)
    assert {"normals.npy", "normals.png", "albedo.npy", "fit.ptm", "fit.rti", "qa.json"} <= set(
        names
    )


def test_several_bands_run_through_dask(session: Path, tmp_path: Path, monkeypatch) -> None:
    """With small bands (many chunks, several computed at once) the bytes still agree."""
    from rti_rig.app.usecases import fit as fit_mod
    from rti_rig.app.usecases.fit import FitRequest, run_fit
    from rti_rig.app.usecases.fit_dask import run_fit_dask

    monkeypatch.setattr(fit_mod, "BAND_BUDGET_BYTES", 36 * 88 * 3 * 4 * 5)  # 5-row bands
    req = FitRequest(session, tmp_path / "plain", model="ps", qa=False)
    run_fit(req)
    run_fit_dask(FitRequest(session, tmp_path / "dask", model="ps", qa=False), "threads")
    same_files(tmp_path / "plain", tmp_path / "dask")


def unreadable(path: Path) -> np.ndarray:
    """An opener standing for a worker that does not see the session's files."""
    raise FileNotFoundError(2, "No such file or directory", str(path))


def test_a_worker_that_cannot_read_the_images_is_a_clear_error(
    session: Path, tmp_path: Path, monkeypatch
) -> None:
    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask
    from rti_rig.app.usecases.fit import FitRequest

    # the client (this process) reads the .lp, the sample and the QA crop; the in-process
    # workers open the files with the opener the lazy stack names
    monkeypatch.setattr(fit_dask, "read_image", unreadable)
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        address = cluster.scheduler_address
        req = FitRequest(session, tmp_path / "out", model="ps", qa=False)
        with pytest.raises(fit_dask.SchedulerError) as caught:
            fit_dask.run_fit_dask(req, address)
    text = str(caught.value)
    assert address in text and "image_001.tif" in text and "same paths" in text
    # the failed fit closed and removed its half-written relightable files
    out = tmp_path / "out"
    assert not list(out.rglob("*.part")), sorted(out.rglob("*"))


def test_the_threads_batch_is_resumable(session: Path, tmp_path: Path) -> None:
    second = tmp_path / "second"
    shutil.copytree(session, second)
    out = tmp_path / "batch"
    args = ["fit", str(session), str(second), "--out", str(out), "--model", "ps", "--no-qa"]
    r = runner.invoke(app, [*args, "--scheduler", "threads"])
    said = " ".join(r.output.split())  # a long tmp path wraps a line between name and outcome
    assert r.exit_code == 0 and said.count(": done") == 2, r.output
    # a killed run: the second session's folder is gone, a partial one was left behind
    shutil.rmtree(out / "second")
    left = out / f".second.{dead_pid()}-abcd.partial"  # a killed run's
    left.mkdir()
    (left / "junk").write_text("x")
    first_bytes = (out / session.name / "normals.npy").read_bytes()
    r = runner.invoke(app, [*args, "--scheduler", "threads"])
    assert r.exit_code == 0, r.output
    said = " ".join(r.output.split())
    assert said.count("(finished earlier)") == 1 and said.count(": done") == 1, r.output
    assert not list(out.glob(".*partial")) and not (out / "second" / "junk").exists()
    assert (out / session.name / "normals.npy").read_bytes() == first_bytes
    plain = tmp_path / "plain"
    r = runner.invoke(app, ["fit", str(second), "--out", str(plain), "--model", "ps", "--no-qa"])
    assert r.exit_code == 0, r.output
    for name in ("normals.npy", "normals.png", "albedo.npy", "fit.ptm", "fit.rti"):
        assert (plain / name).read_bytes() == (out / "second" / name).read_bytes(), name


def test_eight_bit_images_beside_a_bare_lp_give_the_same_bytes(session: Path, tmp_path: Path):
    """Images that cannot be read by rows (8-bit PNG, decoded whole from sRGB) go through the
    lazy stack too, decoded once per process."""
    import cv2
    import tifffile

    from rti_rig.core.lp_format import LpEntry, read_lp, write_lp

    folder = tmp_path / "png"
    folder.mkdir()
    entries = []
    for e in read_lp(session / "lights.lp"):
        name = Path(e.name).stem + ".png"
        linear = tifffile.imread(session / "linear" / (Path(e.name).stem + ".tif")) / 65535.0
        srgb = np.where(linear <= 0.0031308, linear * 12.92, 1.055 * linear ** (1 / 2.4) - 0.055)
        cv2.imwrite(str(folder / name), np.round(srgb[..., ::-1] * 255).astype(np.uint8))
        entries.append(LpEntry(name, e.direction))
    write_lp(folder / "dome.lp", entries)
    base = ["fit", str(folder / "dome.lp"), "--model", "ps", "--no-qa"]
    r = runner.invoke(app, [*base, "--out", str(tmp_path / "plain")])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, [*base, "--out", str(tmp_path / "threads"), "--scheduler", "threads"])
    assert r.exit_code == 0, r.output
    same_files(tmp_path / "plain", tmp_path / "threads")


def test_a_killed_attempts_partial_folder_goes_once_the_session_is_finished(
    session: Path, tmp_path: Path
) -> None:
    """A Dask worker killed mid-session cannot remove its attempt's partial folder; the retry
    finished the session, and the dead attempt's folder (hundreds of MB of a large session)
    had stayed in --out after a successful batch, never removed (finished sessions are
    skipped). Another session's partial folder whose name begins alike is left alone."""
    from rti_rig.app.usecases.fit import FitRequest
    from rti_rig.app.usecases.fit_batch import fit_one

    root = tmp_path / "batch"
    dead = root / f".{session.name}.{dead_pid()}-dead0000.partial"  # the killed worker's attempt
    other = root / f".{session.name}.x.777-live0000.partial"  # session "s.x", being fitted
    for folder in (dead, other):
        folder.mkdir(parents=True)
        (folder / "normals.npy").write_bytes(b"half")
    item = fit_one(session, root, FitRequest(session, root, model="ps", qa=False))
    assert item.status == "done", item.status
    assert not dead.exists() and (other / "normals.npy").exists()
    # and a later run removes one left beside a finished session
    dead.mkdir()
    args = ["fit", str(session), str(tmp_path / "nope"), "--out", str(root), "--no-qa"]
    r = runner.invoke(app, args)
    assert "(finished earlier)" in r.output and not dead.exists(), r.output


class _Records(logging.Handler):
    """The records that reach the handlers of Dask's client logger (what a user sees)."""

    def __init__(self) -> None:
        super().__init__()
        self.texts: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.texts.append(record.getMessage())


def _fetches_failing(cluster, times: int) -> dict[str, int]:  # type: ignore[no-untyped-def]
    """The in-process worker's answer to a fetch of a result fails ``times`` times (a worker
    lost with its results, or one the scheduler cannot connect to), then serves it."""
    (worker,) = cluster.workers.values()
    serve, calls = worker.handlers["get_data"], {"n": 0}

    async def get_data(comm, **kwargs):  # type: ignore[no-untyped-def]
        calls["n"] += 1  # Dask hands the handler its comm by the parameter's name
        if calls["n"] <= times:
            raise OSError("connection reset by peer")
        return await serve(comm, **kwargs)

    worker.handlers["get_data"] = get_data
    return calls


@pytest.fixture
def client_log():  # type: ignore[no-untyped-def]
    handler = _Records()
    logger = logging.getLogger("distributed.client")
    logger.addHandler(handler)
    yield handler.texts
    logger.removeHandler(handler)


def test_a_result_fetched_again_after_a_failed_fetch_says_nothing(
    session: Path, tmp_path: Path, client_log: list[str]
) -> None:
    """Dask fetches a result again when a fetch fails (its worker lost, say): the fit is the
    same, and the user's stderr had a WARNING "Couldn't gather 1 keys, rescheduling …" of a
    run that went well."""
    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask
    from rti_rig.app.usecases.fit import FitRequest, run_fit

    run_fit(FitRequest(session, tmp_path / "plain", model="ps", qa=False))
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        calls = _fetches_failing(cluster, 1)
        req = FitRequest(session, tmp_path / "dask", model="ps", qa=False)
        fit_dask.run_fit_dask(req, cluster.scheduler_address)
    assert calls["n"] >= 2  # the fetch did fail once
    same_files(tmp_path / "plain", tmp_path / "dask")
    assert not [t for t in client_log if "Couldn't gather" in t], client_log


@pytest.fixture
def scripted_clock(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[float]]:
    """The fetch watch's clock, 30 s on at each reading: a result that never comes is given
    up after its tries without a minute of real waiting. Its readings are kept: a test that
    ends without any was not given up by this clock."""
    from rti_rig.app.usecases import fit_dask

    readings: list[float] = []

    def clock() -> float:
        readings.append(30.0 * len(readings))
        return readings[-1]

    watched = fit_dask._gathers_watched
    monkeypatch.setattr(fit_dask, "_gathers_watched", lambda client: watched(client, clock))
    yield readings
    assert len(readings) >= fit_dask.GATHER_TRIES, readings  # the watch measured by it


@pytest.mark.usefixtures("scripted_clock")
def test_a_result_that_can_never_be_fetched_is_a_named_error(
    session: Path, tmp_path: Path, client_log: list[str]
) -> None:
    """A worker whose results cannot be fetched (one the scheduler cannot connect to): Dask
    retried for ever, hundreds of "Couldn't gather" warnings a second, and the fit never
    ended. It stops after a few tries, saying what to check."""
    import threading

    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask
    from rti_rig.app.usecases.fit import FitRequest

    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        _fetches_failing(cluster, 10**9)
        address = cluster.scheduler_address
        req = FitRequest(session, tmp_path / "out", model="ps", qa=False)
        caught: list[BaseException] = []

        def fit() -> None:
            try:
                fit_dask.run_fit_dask(req, address)
            except BaseException as exc:  # handed to the test's thread
                caught.append(exc)

        worker = threading.Thread(target=fit, daemon=True)
        worker.start()
        worker.join(timeout=120)  # a bound on a hang, not a timing: it ends in about a second
        assert not worker.is_alive(), f"the fit still waits ({len(client_log)} log lines)"
    assert len(caught) == 1 and isinstance(caught[0], fit_dask.SchedulerError), caught
    text = str(caught[0])
    assert address in text and "could not be fetched" in text and "--contact-address" in text
    assert not [t for t in client_log if "Couldn't gather" in t], client_log[:3]
    assert not list((tmp_path / "out").rglob("*.part"))


@pytest.mark.usefixtures("scripted_clock")
def test_a_batch_session_whose_report_can_never_be_fetched_is_said_finished(
    session: Path, tmp_path: Path, client_log: list[str]
) -> None:
    """In a batch the session whose result cannot be fetched ends the wait (its `.result()`
    had waited for ever too). Its fit ended on the worker, its output in place: it had been
    said "failed", and a rerun skipped it as "finished earlier"."""
    import threading

    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask
    from rti_rig.app.usecases.fit import FitRequest

    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        _fetches_failing(cluster, 10**9)
        address = cluster.scheduler_address
        root = tmp_path / "batch"
        template = FitRequest(session, root, model="ps", qa=False)
        items: list = []
        batch = threading.Thread(
            target=lambda: items.extend(
                fit_dask.run_batch_dask([session], root, template, address)
            ),
            daemon=True,
        )
        batch.start()
        batch.join(timeout=120)  # a bound on a hang, not a timing
        assert not batch.is_alive(), "the batch still waits"
    (item,) = items
    out = root / session.name
    assert item.status == (
        f"finished on its worker; its report could not be fetched (its outputs are in {out})"
    ), item.status
    assert out.is_dir()
    assert not [t for t in client_log if "Couldn't gather" in t], client_log[:3]


def test_a_fetch_failing_for_under_a_second_is_ridden_through(
    session: Path, tmp_path: Path, client_log: list[str]
) -> None:
    """A refused or reset fetch fails 5 times in about half a second: counting tries alone
    ended the fit on a network blip Dask rides through. It is given up only after the tries
    and GATHER_PATIENCE_S (here, the real clock: far from a minute)."""
    from distributed import LocalCluster

    from rti_rig.app.usecases import fit_dask
    from rti_rig.app.usecases.fit import FitRequest, run_fit

    run_fit(FitRequest(session, tmp_path / "plain", model="ps", qa=False))
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        calls = _fetches_failing(cluster, fit_dask.GATHER_TRIES + 3)
        req = FitRequest(session, tmp_path / "dask", model="ps", qa=False)
        fit_dask.run_fit_dask(req, cluster.scheduler_address)
    assert calls["n"] > fit_dask.GATHER_TRIES + 3
    same_files(tmp_path / "plain", tmp_path / "dask")


class _Loop:
    def __init__(self) -> None:
        self.callbacks: list = []

    def add_callback(self, fn) -> None:  # type: ignore[no-untyped-def]
        self.callbacks.append(fn)


class _Client:
    def __init__(self) -> None:
        self.loop = _Loop()


class _Future:
    def __init__(self, key: str) -> None:
        self.key = key


def _gather_failed(*keys: str) -> logging.LogRecord:
    return logging.LogRecord(
        "distributed.client", logging.WARNING, __file__, 1,
        "Couldn't gather %s keys, rescheduling %s", (len(keys), keys), None,
    )  # fmt: skip


def test_the_fetch_watch_gives_up_after_its_tries_and_its_time_both() -> None:
    """Five failures and a minute since the first, not five failures alone."""
    from rti_rig.app.usecases.fit_dask import GATHER_PATIENCE_S, GATHER_TRIES, _GatherWatch

    now = [0.0]
    client = _Client()
    watch = _GatherWatch(client, clock=lambda: now[0])
    watch.track(_Future("k"))
    for _ in range(GATHER_TRIES + 5):
        assert watch.filter(_gather_failed("k")) is False  # hidden
    assert client.loop.callbacks == []
    now[0] = GATHER_PATIENCE_S
    watch.filter(_gather_failed("k"))
    watch.filter(_gather_failed("k"))
    assert len(client.loop.callbacks) == 1  # cancelled once


def test_two_fits_in_one_process_each_count_their_own_fetches() -> None:
    """The filter hid "Couldn't gather" of every result: the first fit's watch stopped the
    record before the second's saw it, so the second never counted and would wait for ever."""
    from rti_rig.app.usecases.fit_dask import GATHER_TRIES, _gathers_watched

    first_client, second_client = _Client(), _Client()
    logger = logging.getLogger("distributed.client")

    def clock() -> float:  # a minute gone by once the second watch counted a failure
        return 1e9 if second.failures else 0.0

    with (
        _gathers_watched(first_client, clock) as first,
        _gathers_watched(second_client, clock) as second,
    ):
        second.track(_Future("theirs"))
        for _ in range(GATHER_TRIES + 1):
            logger.filter(_gather_failed("theirs"))
    assert first.failures == {} and second.failures["theirs"] == GATHER_TRIES + 1
    assert len(second_client.loop.callbacks) == 1 and first_client.loop.callbacks == []
