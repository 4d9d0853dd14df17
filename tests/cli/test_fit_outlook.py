"""What `rti-rig fit` will make of a session of N lights is said by run and plan beforehand, in
the fit's own figures, and their refusals of too few lights are worded alike.

``run --lights 3`` had said nothing (its QA verdict "good"), then plain ``fit`` failed ("--model
auto: no candidate model can be fitted from 3 image(s)"); at 4 or 5 lights nothing said that no
fit.ptm would be written. ``run --lights 0`` said "at least 1 light", ``plan --lights 0`` "plan at
least 3", each its own way.
"""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
DOME = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"


@pytest.mark.e2e
@pytest.mark.slow
@pytest.mark.parametrize(
    "lights, before, fitted, missing",
    [
        (3, "`rti-rig fit` with its default --model auto cannot fit them", False, ()),
        (4, "will make a normal map but no fit.ptm or fit.rti", True, ("fit.ptm", "fit.rti")),
        (5, "will make a normal map but no fit.ptm (a PTM needs 6)", True, ("fit.ptm",)),
    ],
)
def test_run_says_what_the_fit_will_make_and_the_fit_bears_it_out(
    tmp_path: Path, lights: int, before: str, fitted: bool, missing: tuple[str, ...]
) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    session = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(session), "--lights", str(lights)])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert text.index(before) < text.index("Rig small"), text  # before anything lights
    r = runner.invoke(app, ["fit", str(session), "--out", str(tmp_path / "fit")])
    assert (r.exit_code == 0) is fitted, r.output
    for name in missing:
        assert not (tmp_path / "fit" / name).exists()
    if not fitted:  # what the note offered works
        args = ["fit", str(session), "--out", str(tmp_path / "ps"), "--model", "ps"]
        r = runner.invoke(app, args)
        assert r.exit_code == 0 and (tmp_path / "ps" / "normals.npy").is_file(), r.output


@pytest.mark.parametrize("lights, note", [(3, "default --model auto cannot fit them"), (6, None)])
def test_plan_says_what_the_fit_will_make(tmp_path: Path, lights: int, note: str | None) -> None:
    out = tmp_path / "p.lp"
    args = ["plan", "--rig", str(DOME), "--lights", str(lights), "--out", str(out)]
    r = runner.invoke(app, args)
    assert r.exit_code == 0 and out.is_file(), r.output
    assert (note is None and "`rti-rig fit`" not in said(r)) or (note and note in said(r))


def test_too_few_lights_are_refused_alike_with_the_fits_figures(tmp_path: Path) -> None:
    r = runner.invoke(app, ["run", str(DOME), "--out", str(tmp_path / "s"), "--lights", "0"])
    assert r.exit_code == 2 and not (tmp_path / "s").exists(), r.output
    run_said = said(r)
    assert "--lights 0: give at least 1 light (1 or 2 make a test shot;" in run_said
    r = runner.invoke(app, ["plan", "--lights", "2", "--out", str(tmp_path / "p.lp")])
    assert r.exit_code == 2 and not (tmp_path / "p.lp").exists(), r.output
    plan_said = said(r)
    assert "--lights 2: give at least 3 lights to plan;" in plan_said
    assert "Traceback" not in plan_said
    # the test shot's command, real (it had said "rti-rig run RIG --lights 1"), runs as said
    shot = tmp_path / "test-shot"
    command = plan_said.split("needs no plan: ", 1)[1].split(f" --out {shot}", 1)[0]
    assert command.startswith("rti-rig run ") and " --lights 1" in command, plan_said
    r = runner.invoke(app, [*shlex.split(command)[1:], "--out", str(shot), "--no-verdict"])
    assert r.exit_code == 0 and (shot / "lights.lp").read_text().startswith("1"), r.output
    for text in (run_said, plan_said):  # the fit's own figures, in the same words
        assert "needs 3 for a normal map with --model ps, 4 for its default --model auto" in text
