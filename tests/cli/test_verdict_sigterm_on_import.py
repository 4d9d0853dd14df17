"""A SIGTERM as ``run``'s QA verdict loads its code is said as one during the verdict.

An audit sent SIGTERM to ``rti-rig run rig_configs/simulated_arm.toml`` just after "Lamp off":
the handler's ``Terminated`` landed while ``print_verdict`` imported the fit's code, outside
the ``try`` that says it, and a traceback ended a complete session with exit 1.
"""

from __future__ import annotations

import builtins
from pathlib import Path

import pytest
import typer

from rti_rig.cli import fit as cli_fit
from rti_rig.cli.stopping import Terminated


def test_a_sigterm_while_the_verdict_s_code_loads_is_said_and_exits_143(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    real_import = builtins.__import__

    def import_hit_by_sigterm(name, *args, **kwargs):  # type: ignore[no-untyped-def]
        if name == "rti_rig.app.usecases.fit":
            raise Terminated  # where the run's SIGTERM handler raises it
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", import_hit_by_sigterm)
    with pytest.raises(typer.Exit) as info:
        cli_fit.print_verdict(tmp_path / "S")
    monkeypatch.undo()
    assert info.value.exit_code == 143
    said = " ".join(capsys.readouterr().err.split())
    assert "QA verdict skipped (SIGTERM): the session is complete" in said, said
