"""`rti-rig fit --scheduler` on a cluster whose workers run other versions of the libraries the
fit's tasks pass through (distributed, dask, cloudpickle; numpy's major): refused before any
band is sent, naming the workers, their versions and the ones to install. A worker of
distributed 2025.1.0 under a 2026.8.0 client had died on its first task (``TypeError:
ComputeTaskEvent…``) and the fit said, 80 s later, only that the checked workers "have all
left"."""

from __future__ import annotations

import os
import subprocess
import sys
import warnings
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.app.usecases.worker_code import (
    STACK_PACKAGES,
    WorkerCode,
    local_identity,
    stack_differences,
)
from rti_rig.cli import app

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

runner = CliRunner()

#: A `dask worker` whose distributed and dask say they are 2025.1.0: what the check reads on a
#: worker of that release (the imported modules' ``__version__``), without a second venv; its
#: installed metadata says so too (:func:`older_metadata`), as Dask's own version table reads.
OLDER_DASK_WORKER = (
    "import dask, distributed\n"
    "dask.__version__ = distributed.__version__ = '2025.1.0'\n"
    "from distributed.cli.dask_worker import main\n"
    "main()\n"
)


def older_metadata(where: Path) -> Path:
    """A folder that, first on a worker's ``sys.path``, makes ``importlib.metadata`` (which
    Dask's version table reads) say distributed and dask 2025.1.0."""
    for name in ("distributed", "dask"):
        info = where / f"{name}-2025.1.0.dist-info"
        info.mkdir(parents=True)
        meta = f"Metadata-Version: 2.1\nName: {name}\nVersion: 2025.1.0\n"
        (info / "METADATA").write_text(meta, encoding="utf-8")
    return where


def test_a_worker_of_another_distributed_is_refused_before_any_band(tmp_path: Path) -> None:
    import dask
    import distributed
    from distributed import Client, LocalCluster
    from distributed.versions import VersionMismatchWarning

    session = make_session(tmp_path / "A", size=(24, 32))[0]
    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        protocol="tcp",  # reachable from the worker process
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:
        address = cluster.scheduler_address
        ours = set(cluster.scheduler.workers)
        worker = subprocess.Popen(
            [sys.executable, "-c", OLDER_DASK_WORKER, address, "--nthreads", "1",
             "--no-nanny", "--no-dashboard"],
            cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            env={**os.environ, "PYTHONPATH": str(older_metadata(tmp_path / "meta"))},
        )  # fmt: skip
        try:
            with Client(address, set_as_default=False) as watcher:
                watcher.wait_for_workers(2, timeout=300)  # a bound on a hang, not a timing
                (other,) = set(watcher.scheduler_info()["workers"]) - ours
            out = tmp_path / "F"
            args = ["fit", str(session), "--out", str(out), "--no-qa", "--model", "ps"]
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                r = runner.invoke(app, [*args, "--scheduler", address])
        finally:
            worker.terminate()
            worker.wait(timeout=120)
    assert r.exit_code == 2, r.output
    said = " ".join(r.output.split())
    assert f"1 of the 2 workers of the Dask cluster at '{address}' run other versions" in said
    assert f"{other} (distributed 2025.1.0, dask 2025.1.0)" in said, said
    mine = f"distributed {distributed.__version__}, dask {dask.__version__}"
    assert f"than this machine ({mine})" in said, said
    assert (
        f"pip install 'distributed=={distributed.__version__}' 'dask=={dask.__version__}'" in said
    ), said
    assert "have all left" not in said and "Traceback" not in r.output
    # Dask's own table of the same versions is not said besides this command's words
    assert not [w for w in caught if issubclass(w.category, VersionMismatchWarning)], caught
    assert not out.exists()


def _with(**versions: str) -> WorkerCode:
    """This process's identity with ``versions`` in its stack; a Python only when given (an
    rti-rig before 2026-12-01 reported none)."""
    here = local_identity()
    stack = tuple((name, versions.get(name, dict(here.stack)[name])) for name, _ in STACK_PACKAGES)
    if "python" in versions:
        stack = (("python", versions["python"]), *stack)
    return WorkerCode(here.version, here.fingerprint, here.problem, stack)


#: This machine's Python, as a worker's must agree (its minor), and the next minor version.
OURS = f"{sys.version_info[0]}.{sys.version_info[1]}"
NEXT = f"{sys.version_info[0]}.{sys.version_info[1] + 1}"

#: A `dask worker` whose Python says it is the next minor version: what Dask's version report
#: and the rti-rig check read on a worker of that Python (``sys.version_info``), without a
#: second interpreter; set once Dask is imported, so that no import takes the other's paths.
OTHER_PYTHON_WORKER = (
    "import collections, sys\n"
    "from distributed.cli.dask_worker import main\n"
    "Info = collections.namedtuple('version_info', 'major minor micro releaselevel serial')\n"
    "sys.version_info = Info(sys.version_info[0], sys.version_info[1] + 1, 0, 'final', 0)\n"
    "main()\n"
)


def test_a_worker_of_another_python_minor_is_refused_naming_both(tmp_path: Path) -> None:
    """cloudpickle sends the fit's functions as this Python's byte code, which another minor
    version cannot run: the worker is refused before any function of ours is sent, naming it,
    both Pythons and what to do (its distributed and dask agree, so that alone refuses it)."""
    from distributed import Client, LocalCluster

    session = make_session(tmp_path / "A", size=(24, 32))[0]
    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        protocol="tcp",  # reachable from the worker process
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:
        address = cluster.scheduler_address
        ours = set(cluster.scheduler.workers)
        worker = subprocess.Popen(
            [sys.executable, "-c", OTHER_PYTHON_WORKER, address, "--nthreads", "1",
             "--no-nanny", "--no-dashboard"],
            cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        try:
            with Client(address, set_as_default=False) as watcher:
                watcher.wait_for_workers(2, timeout=300)  # a bound on a hang, not a timing
                (other,) = set(watcher.scheduler_info()["workers"]) - ours
            out = tmp_path / "F"
            args = ["fit", str(session), "--out", str(out), "--no-qa", "--model", "ps"]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # Dask's own table of the versions
                r = runner.invoke(app, [*args, "--scheduler", address])
        finally:
            worker.terminate()
            worker.wait(timeout=120)
    assert r.exit_code == 2, r.output
    said = " ".join(r.output.split())
    assert f"1 of the 2 workers of the Dask cluster at '{address}' run another Python" in said
    assert f"than this machine (Python {OURS}): {other} (Python {NEXT})" in said, said
    assert f"run those workers under Python {OURS}" in said, said
    assert "Traceback" not in r.output and "could not be asked" not in said
    assert not out.exists()


def test_numpy_is_compared_by_major_and_the_dask_libraries_exactly() -> None:
    """numpy's array pickles are read across one major version, not from 2 to 1; distributed,
    dask and cloudpickle must agree to the release."""
    mine = local_identity()
    major = dict(mine.stack)["numpy"]
    assert major.endswith(".x") and not stack_differences(mine, _with())
    assert stack_differences(mine, _with(numpy="1.x")) == [("numpy", major, "1.x")]
    assert [d[0] for d in stack_differences(mine, _with(cloudpickle="2.2.1"))] == ["cloudpickle"]
    assert [d[2] for d in stack_differences(mine, _with(dask=""))] == [""]  # none there
    # an rti-rig from before this check reports no versions: its code differs, said as such
    older = WorkerCode(mine.version, "0123456789ab", None)
    assert stack_differences(mine, older) == []


def test_python_is_compared_to_its_minor_version_when_reported() -> None:
    mine = local_identity()
    assert dict(mine.stack)["python"] == OURS
    assert not stack_differences(mine, _with(python=OURS))
    assert stack_differences(mine, _with(python=NEXT)) == [("python", OURS, NEXT)]
    # reported by no rti-rig before this one: not compared (its code differs, said as such)
    assert not stack_differences(mine, _with())


def test_a_worker_joining_later_with_another_distributed_is_not_tagged() -> None:
    """The plugin that tags each worker as it joins (a nanny's restart mid-fit) gives no tag,
    and so no task, to one of other library versions, and says why."""
    import asyncio
    from types import SimpleNamespace

    from rti_rig.app.usecases.worker_code import OTHER_CODE, tagging_plugin

    mine = local_identity()
    plugin = tagging_plugin(mine)
    real = plugin.identity
    plugin.identity = lambda: {**real(), "stack": {**dict(mine.stack), "distributed": "2025.1.0"}}
    given: list[dict[str, float]] = []

    async def set_resources(**resources: float) -> None:
        given.append(resources)

    worker = SimpleNamespace(
        state=SimpleNamespace(total_resources={}), set_resources=set_resources, status=None
    )
    asyncio.run(plugin.setup(worker))
    kind, words = plugin.outcome
    assert kind == OTHER_CODE and not given, (kind, words)
    assert "distributed 2025.1.0 (this fit's " in words, words


def test_a_worker_joining_later_with_another_python_is_not_tagged() -> None:
    """A worker that joins after the cluster was checked (a nanny's restart) under another
    Python: not tagged, if the check runs there at all, and said why."""
    import asyncio
    from types import SimpleNamespace

    from rti_rig.app.usecases.worker_code import OTHER_CODE, tagging_plugin

    mine = local_identity()
    plugin = tagging_plugin(mine)
    real = plugin.identity
    plugin.identity = lambda: {**real(), "stack": {**dict(mine.stack), "python": NEXT}}
    given: list[dict[str, float]] = []

    async def set_resources(**resources: float) -> None:
        given.append(resources)

    worker = SimpleNamespace(
        state=SimpleNamespace(total_resources={}), set_resources=set_resources, status=None
    )
    asyncio.run(plugin.setup(worker))
    kind, words = plugin.outcome
    assert kind == OTHER_CODE and not given, (kind, words)
    assert f"python {NEXT} (this fit's {OURS})" in words, words
