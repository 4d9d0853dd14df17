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


def _set_status(status: str, dask_worker: Any) -> None:
    """Set the worker's status as a user's ``client.run`` (or its memory monitor) does."""
    from distributed.core import Status

    dask_worker.status = Status[status]


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


def test_a_paused_worker_is_tagged_but_not_resumed_and_takes_the_waiting_task_when_it_resumes() -> (
    None
):
    """The tag wakes the tasks waiting for a tagged worker by pausing and resuming a worker that
    is running; a worker paused (for memory, or by a user's ``client.run``) must stay paused:
    resuming it would override the memory monitor or the user."""
    from distributed import Client, LocalCluster
    from distributed.core import Status

    mine = local_identity()
    with (
        LocalCluster(
            n_workers=1,
            threads_per_worker=1,
            processes=False,
            dashboard_address=None,
            memory_limit=0,  # no memory monitor to resume it by itself
        ) as cluster,
        Client(cluster, set_as_default=False) as client,
    ):
        (worker,) = cluster.workers.values()
        client.run(_set_status, "paused")  # on the worker's own event loop
        future = client.submit(operator.add, 1, 2, resources={tag_for(mine): 1}, pure=False)
        _until(
            lambda: getattr(cluster.scheduler.tasks.get(future.key), "state", "") == "no-worker",
            "the task never waited for a tagged worker",
        )
        client.register_plugin(tagging_plugin(mine), name="rti-rig-test-paused")
        assert tag_for(mine) in cluster.scheduler.workers[worker.address].resources
        assert worker.status == Status.paused  # setup has run: register_plugin waited for it
        assert cluster.scheduler.tasks[future.key].state == "no-worker"
        client.run(_set_status, "running")
        assert future.result(timeout=300) == 3  # a bound on a hang: it runs at once
