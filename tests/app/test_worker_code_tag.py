"""The resource that marks a Dask worker checked to run this rti-rig
(:func:`rti_rig.app.usecases.worker_code.tagging_plugin`): given only to a worker whose own
code is this one, and a task already waiting for such a worker runs once one is tagged (Dask
reconsiders a waiting task when a worker joins or resumes, not when it gains a resource)."""

from __future__ import annotations

import operator
import time
from typing import Any

from rti_rig.app.usecases.worker_code import (
    WorkerCode,
    local_identity,
    tag_for,
    tagging_plugin,
)


def _until(condition: Any, what: str, timeout: float = 300.0) -> None:
    """Wait for ``condition()`` (a bound on a hang, not a timing)."""
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, what
        time.sleep(0.05)


def _cluster() -> Any:
    from distributed import LocalCluster

    return LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None)


def test_a_task_waiting_for_a_checked_worker_runs_once_the_worker_is_tagged() -> None:
    from distributed import Client

    mine = local_identity()
    with _cluster() as cluster, Client(cluster, set_as_default=False) as client:
        future = client.submit(operator.add, 1, 2, resources={tag_for(mine): 1}, pure=False)
        _until(
            lambda: getattr(cluster.scheduler.tasks.get(future.key), "state", "") == "no-worker",
            "the task never waited for a tagged worker",
        )
        client.register_plugin(tagging_plugin(mine), name="rti-rig-test-tag")
        assert future.result(timeout=300) == 3  # a bound on a hang: it runs at once


def test_a_worker_running_other_code_is_not_tagged() -> None:
    from distributed import Client

    mine = local_identity()
    other = WorkerCode("0.0.9-other", "0123456789ab")
    with _cluster() as cluster, Client(cluster, set_as_default=False) as client:
        client.register_plugin(tagging_plugin(other), name="rti-rig-test-other")
        client.register_plugin(tagging_plugin(mine), name="rti-rig-test-mine")
        (worker,) = cluster.scheduler.workers.values()
        assert tag_for(mine) in worker.resources
        assert tag_for(other) not in worker.resources
