"""A Ctrl-C once `rti-rig plan` has written its plan says the plan is written and leaves no
partial map.

Why: a Ctrl-C while the map was drawn said only "rti-rig: stopped (Ctrl-C)", with the plan on
disk (the next run refused its --out), and matplotlib, writing under the name asked, could leave
a partial map there.
"""

from __future__ import annotations

import signal
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS
from matplotlib.figure import Figure
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_ctrl_c_while_the_map_is_written_says_the_plan_is_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    raised: list[str] = []

    def savefig(self: Figure, fname: Any, *args: Any, **kwargs: Any) -> None:
        Path(fname).write_bytes(b"\x89PNG\r\n\x1a\n half a map")  # as far as it got
        raised.append(str(fname))
        signal.raise_signal(signal.SIGINT)  # the user's Ctrl-C, mid-write

    monkeypatch.setattr(Figure, "savefig", savefig)
    plan, figure = tmp_path / "plan é.lp", tmp_path / "map é.png"
    argv = ["plan", "--rig", str(CONFIGS / "virtual_arm.toml"), "--method", "optimal"]

    r = CliRunner().invoke(app, [*argv, "--out", str(plan), "--figure", str(figure)])

    said = " ".join(r.output.split())
    assert len(raised) == 1, said
    assert r.exit_code == 130, said
    assert "Traceback" not in said, said
    assert (
        f"Stopped (Ctrl-C): the plan {plan} is written (12 lights); the map {figure} was not drawn"
        in said
    ), said
    assert len(read_lp(plan)) == 12
    assert not figure.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == [plan.name]


def test_a_ctrl_c_once_the_map_is_written_says_it_is_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from rti_rig.cli import plan as plan_cli

    printed = plan_cli.out.print

    def interrupted(*args: Any, **kwargs: Any) -> None:
        if args and str(args[0]).startswith("Map of the plan"):
            raise KeyboardInterrupt  # the user's Ctrl-C, as the map's line is printed
        printed(*args, **kwargs)

    monkeypatch.setattr(plan_cli.out, "print", interrupted)
    plan, figure = tmp_path / "plan.lp", tmp_path / "map.png"
    argv = ["plan", "--rig", str(CONFIGS / "virtual_arm.toml"), "--method", "optimal"]

    r = CliRunner().invoke(app, [*argv, "--out", str(plan), "--figure", str(figure)])

    said = " ".join(r.output.split())
    assert r.exit_code == 130, said
    assert f"the plan {plan} is written (12 lights); the map {figure} is written" in said, said
    assert "not drawn" not in said, said
    assert figure.read_bytes().startswith(b"\x89PNG")
