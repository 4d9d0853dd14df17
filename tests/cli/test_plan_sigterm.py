"""A SIGTERM during `rti-rig plan` stops it as Ctrl-C does: no hidden partial map left, what was
written said, exit 143.

Why: plan had no SIGTERM handler (run and fit have theirs): a SIGTERM (``timeout``, a scheduler)
while the map was written ended the process at once, leaving a hidden ``.map.partial.png``
beside the plan, and said nothing. The signal is sent to this process from inside the command,
at the point under test (no sleeps).
"""

from __future__ import annotations

import signal
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, said
from matplotlib.figure import Figure
from sigterm_support import Unhandled, sigterm_fails_the_test, terminated
from typer.testing import CliRunner

from rti_rig.app.usecases import plan as plan_usecase
from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")

runner = CliRunner()
ARGV = ["plan", "--rig", str(CONFIGS / "virtual_arm.toml"), "--method", "optimal"]


@pytest.fixture(autouse=True)
def _sigterm_fails_the_test_not_the_run() -> Iterator[None]:
    with sigterm_fails_the_test("plan"):
        yield


def test_a_sigterm_while_the_map_is_written_leaves_no_partial_map(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    written: list[Path] = []

    def savefig(self: Figure, fname: Any, *args: Any, **kwargs: Any) -> None:
        Path(fname).write_bytes(b"\x89PNG\r\n\x1a\n half a map")  # as far as it got
        written.append(Path(fname))
        terminated()

    monkeypatch.setattr(Figure, "savefig", savefig)
    plan, figure = tmp_path / "plan é.lp", tmp_path / "map é.png"

    r = runner.invoke(app, [*ARGV, "--out", str(plan), "--figure", str(figure)])

    text = said(r)
    assert len(written) == 1 and written[0].name.startswith("."), text  # the hidden partial
    assert r.exit_code == 143, text
    assert not isinstance(r.exception, Unhandled), text
    assert "Traceback" not in text, text
    assert (
        f"Stopped (SIGTERM): the plan {plan} is written (12 lights); the map {figure} was not drawn"
    ) in text, text
    assert len(read_lp(plan)) == 12
    assert sorted(p.name for p in tmp_path.iterdir()) == [plan.name]  # no .map é.partial.png
    assert signal.getsignal(signal.SIGTERM).__name__ == "unhandled"  # the command's only


def test_a_sigterm_while_planning_says_no_plan_was_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real = plan_usecase.plan

    def stopped(*args: Any, **kwargs: Any) -> Any:
        terminated()
        return real(*args, **kwargs)

    monkeypatch.setattr(plan_usecase, "plan", stopped)
    plan = tmp_path / "plan.lp"

    r = runner.invoke(app, [*ARGV, "--out", str(plan)])

    text = said(r)
    assert r.exit_code == 143, text
    assert not isinstance(r.exception, Unhandled), text
    assert f"Stopped (SIGTERM) while planning: no plan was written to {plan}" in text, text
    assert list(tmp_path.iterdir()) == []
