"""What a fit says when no worker checked to run this rti-rig has been in the cluster for
:data:`~rti_rig.app.usecases.fit_dask.CHECKED_GRACE_S`: who is there now, only as the
scheduler said it.

Found by a review: a scheduler that did not answer the question (lost meanwhile) was said
as "no worker is there now", a state nobody had established."""

from __future__ import annotations

from typing import Any

from rti_rig.app.usecases.fit_dask import Cluster, checked_gone


class _Client:
    """A Dask client whose scheduler answers ``workers`` or, given None, fails."""

    def __init__(self, workers: dict[str, Any] | None) -> None:
        self.workers = workers

    def scheduler_info(self, n_workers: int = 5) -> dict[str, Any]:
        if self.workers is None:
            raise OSError("Timed out trying to connect to tcp://127.0.0.1:8786")
        return {"workers": self.workers}


def _said(workers: dict[str, Any] | None) -> str:
    cluster = Cluster(_Client(workers), "tcp://127.0.0.1:8786", frozenset({"tcp://w:1"}), "t")
    return checked_gone(cluster, "nothing of this fit was kept in --out")


def test_a_scheduler_that_did_not_answer_is_not_said_to_have_no_worker() -> None:
    text = _said(None)
    assert "no worker is there now" not in text, text
    assert "which workers are there now is not known (the scheduler did not answer)" in text


def test_who_is_there_is_said_as_the_scheduler_answered() -> None:
    assert "no worker is there now" in _said({})
    text = _said({"tcp://other:2": {"resources": {}}})
    assert "were refused, their rti-rig being another or none: tcp://other:2" in text, text
