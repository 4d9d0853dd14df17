"""`bench tradeoff --from` answers what it is run for: how many lights this object needs.

Its summary had given 5 planners × 7 counts of cells and left a conservator to read the answer
out of them; on an arm's session it timed the lights as a dome's without a word (QA,
2026-12-05).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from benchmarks.tradeoff import Row
from benchmarks.tradeoff_from import how_many_lights
from rti_rig.cli import app

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay" / "dirs.lp"
COUNTS = (6, 9, 12, 18)


def _row(method: str, n: int, deg: float, db: float, objective: str = "normals", floor=0.0):
    return Row("acq/dirs.lp", method, objective, n, floor, deg, deg, 1.0, "ptm", db, 0.5,
               n * 1.0, float("nan"), 0.0, "hsh1", db)  # fmt: skip


def _rows(errors: dict[tuple[str, str, float], list[float]], dbs=None) -> list[Row]:
    rows = []
    for (method, objective, floor), degs in errors.items():
        for i, (n, deg) in enumerate(zip(COUNTS, degs, strict=False)):
            db = 30.0 if dbs is None else dbs[(method, objective, floor)][i]
            rows.append(_row(method, n, deg, db, objective, floor))
    return [*rows, _row("all", 40, 0.0, 32.0)]


def test_the_fewest_lights_is_from_which_every_larger_count_meets_the_target() -> None:
    errors = {
        # meets 1° at 9, not at 12: counted from 18 (a lucky 9 is no count to rely on)
        ("uniform", "normals", 0.0): [3.0, 0.9, 1.2, 0.8],
        # a high floor has no layout of 18: meets from 9 on what it has
        ("uniform", "normals", 20.0): [1.5, 0.9, 0.7],
        ("optimal", "normals", 0.0): [2.0, 1.5, 1.1, 1.05],  # never within 1°
        ("adaptive", "normals", 0.0): [1.4, 0.95, 0.9, 0.8],
        ("adaptive", "relight", 0.0): [1.9, 1.8, 0.99, 0.9],
    }
    lines = how_many_lights(_rows(errors), 20.0, 2.0, "my-dome.toml")
    one = next(line for line in lines if line.startswith("- **Normals within 1°**"))
    # the fewest: 9, by the floor layout and by adaptive; the first planner's command is given
    assert "from **9 lights**, 18 s a session, with uniform above 20°" in one, one
    assert "`rti-rig run my-dome.toml --out SESSION --lights 9 --min-elevation-deg 20`" in one, one
    assert "adaptive 9" in one and "adaptive for relighting 12" in one and "uniform 18" in one
    assert "not reached by optimal" in one, one
    three = next(line for line in lines if line.startswith("- **Normals within 3°**"))
    assert "from **6 lights** (the fewest the table tries: fewer may do)" in three, three


def test_a_target_no_planner_reaches_is_said_so() -> None:
    errors = {k: [5.0, 4.0, 3.5, 3.2] for k in (
        ("uniform", "normals", 0.0), ("optimal", "normals", 0.0), ("adaptive", "normals", 0.0),
        ("adaptive", "relight", 0.0))}  # fmt: skip
    lines = how_many_lights(_rows(errors), 0.0, 1.0)
    one = next(line for line in lines if line.startswith("- **Normals within 1°**"))
    assert "no planner reaches it up to 18 lights" in one, one
    # the best floor is 0°: no second uniform column
    assert not [line for line in lines if "uniform above" in line]


def test_relighting_is_judged_on_the_written_file_against_every_lights() -> None:
    keys = [("uniform", "normals", 0.0), ("optimal", "normals", 0.0),
            ("adaptive", "normals", 0.0), ("adaptive", "relight", 0.0)]  # fmt: skip
    dbs = {k: [28.0, 30.0, 31.2, 31.6] for k in keys}
    dbs[("adaptive", "relight", 0.0)] = [30.5, 31.0, 31.6, 31.8]
    lines = how_many_lights(_rows({k: [1.0] * 4 for k in keys}, dbs), 0.0, 1.0, "RIG")
    within = next(line for line in lines if line.startswith("- **Relighting within 1 dB**"))
    # every light's file: 32.0 dB; within 1 dB means 31.0 or more
    assert "from **9 lights**, 9 s a session, with adaptive for relighting" in within, within
    assert "`rti-rig run RIG --out SESSION --adaptive --objective relight --lights 9`" in within
    assert "uniform 12" in within, within


def test_the_summary_opens_with_the_advice_and_an_arm_sessions_times_are_said_a_domes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import benchmarks.tradeoff_from as tradeoff_from
    from tests.benchmarks.test_bench_tradeoff_from import _stand_in_rows

    def run(lp: Path, progress: Any) -> Any:
        return _stand_in_rows()

    monkeypatch.setattr(tradeoff_from, "run_tradeoff_from", run)
    session = tmp_path / "session"
    shutil.copytree(ACQ.parent, session)
    (session / "dirs.lp").rename(session / "lights.lp")
    manifest = {"rig": {"kind": "arm", "name": "simulated-arm"}}
    (session / "manifest.json").write_text(json.dumps(manifest), encoding="utf-8")
    out = tmp_path / "o"
    r = CliRunner().invoke(
        app, ["bench", "tradeoff", "--from", str(session), "--out", str(out)], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    text = (out / "summary.md").read_text(encoding="utf-8")
    assert text.index("## How many lights this object needs") < text.index("| N |"), text
    assert "- **Normals within 3°**: from **6 lights**" in text, text
    assert "this acquisition was shot on an arm" in " ".join(text.split()), text
    (session / "manifest.json").write_text(json.dumps({"rig": {"kind": "dome"}}))
    r = CliRunner().invoke(
        app, ["bench", "tradeoff", "--from", str(session), "--out", str(tmp_path / "d")]
    )
    assert r.exit_code == 0, r.output
    assert "shot on an arm" not in (tmp_path / "d" / "summary.md").read_text(encoding="utf-8")


def test_every_advised_command_is_one_rti_rig_parses(tmp_path: Path) -> None:
    """Each command the advice may print is run with a rig config that is not there: refused
    for the config, never as a usage error (the optimal one had been `plan RIG PREVIEW`, which
    `plan` refuses: it takes the rig with --rig)."""
    import shlex

    from benchmarks.tradeoff_from import _PLANNERS

    rig = tmp_path / "no-such-rig.toml"
    for _, _, template in _PLANNERS:
        text = template.replace("{floor:g}", "20").format(rig=rig, n=9)
        text = text.replace("SESSION", str(tmp_path / "s")).replace(
            "plan.lp", str(tmp_path / "p.lp")
        )
        for command in text.split("` then `"):
            words = shlex.split(command)
            assert words[0] == "rti-rig", command
            r = CliRunner().invoke(app, words[1:], terminal_width=400)
            said = " ".join(r.output.split())
            assert r.exit_code == 2 and "no-such-rig.toml" in said, (command, said)
            assert "Usage:" not in said and "No such option" not in said, (command, said)


def test_a_labs_own_targets_are_the_advices(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`--target-deg` and `--target-db` replace the fixed 1°/2°/3° and 0.5/1/2 dB: the advice
    answers the tolerance the lab gives, and the command written in summary.md repeats them
    (pasted, it gives the same advice)."""
    import benchmarks.tradeoff_from as tradeoff_from
    from tests.benchmarks.test_bench_tradeoff_from import _stand_in_rows

    monkeypatch.setattr(tradeoff_from, "run_tradeoff_from", lambda *_a: _stand_in_rows())
    out = tmp_path / "o"
    argv = ["bench", "tradeoff", "--from", str(ACQ), "--out", str(out)]
    argv += ["--target-deg", "4", "--target-deg", "1.5", "--target-db", "0.3"]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    assert r.exit_code == 0, r.output
    text = (out / "summary.md").read_text(encoding="utf-8")
    advice = [line for line in text.splitlines() if line.startswith("- **")]
    assert [line.split("**")[1] for line in advice] == [
        "Normals within 1.5°",
        "Normals within 4°",
        "Relighting within 0.3 dB",
    ], advice
    assert "--target-deg 1.5 --target-deg 4 --target-db 0.3" in text, text
    # the defaults without them
    r = CliRunner().invoke(app, argv[:4], terminal_width=400)
    assert r.exit_code == 0, r.output
    said = [line.split("**")[1] for line in r.output.splitlines() if line.startswith("- **")]
    assert said[:3] == ["Normals within 1°", "Normals within 2°", "Normals within 3°"], said


@pytest.mark.parametrize(
    ("option", "value", "fragment"),
    [
        ("--target-deg", "0", "--target-deg 0: a mean normal error target is above 0"),
        ("--target-deg", "90", "--target-deg 90: a mean normal error target is above 0"),
        ("--target-deg", "nan", "--target-deg nan: a mean normal error target"),
        ("--target-db", "-1", "--target-db -1: a relighting target is the dB below"),
        ("--target-db", "inf", "--target-db inf: a relighting target"),
    ],
)
def test_a_target_no_trade_can_answer_is_refused_by_name_before_anything_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, option: str, value: str, fragment: str
) -> None:
    import benchmarks.tradeoff_from as tradeoff_from

    def never(*_a: object) -> None:
        raise AssertionError("the trade ran")

    monkeypatch.setattr(tradeoff_from, "run_tradeoff_from", never)
    out = tmp_path / "o"
    argv = ["bench", "tradeoff", "--from", str(ACQ), "--out", str(out), option, value]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    assert r.exit_code == 2, r.output
    assert fragment in " ".join(r.output.split()), r.output
    assert not out.exists()


def test_targets_without_an_acquisition_are_refused(tmp_path: Path) -> None:
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--quick", "--target-deg", "2"])
    assert r.exit_code == 2, r.output
    assert "they go with --from ACQ/dirs.lp" in " ".join(r.output.split()), r.output


def test_no_command_is_advised_for_more_lights_than_the_rigs_dome_has(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`--rig` an 8-LED dome: a target the acquisition reaches from 9 lights gets no command
    (it had advised `run RIG --adaptive --lights 36` on an 8-LED dome, which `run` refused),
    and the summary says its counts are the acquisition's; a count the dome can shoot keeps
    its command."""
    import benchmarks.tradeoff_from as tradeoff_from
    from benchmarks.tradeoff import Row
    from benchmarks.tradeoff_from import PER_LIGHT_S

    def row(method: str, n: int, deg: float, objective: str = "normals") -> Row:
        return Row("acq/dirs.lp", method, objective, n, 0.0, deg, deg, 1.0, "ptm", 20.0, 0.5,
                   n * PER_LIGHT_S, float("nan"), 0.0, "hsh1", 20.0)  # fmt: skip

    rows = [row(m, n, {6: 2.5, 9: 1.5}[n]) for n in (6, 9) for m in ("uniform", "optimal")]
    rows += [row("adaptive", n, {6: 2.5, 9: 1.5}[n]) for n in (6, 9)]
    rows += [row("adaptive", n, 2.5, "relight") for n in (6, 9)] + [row("all", 15, 0.0)]
    monkeypatch.setattr(tradeoff_from, "run_tradeoff_from", lambda *_a: (rows, ["a.jpg"]))
    rig = Path(__file__).resolve().parents[2] / "rig_configs" / "emulated_rtipy.toml"
    assert tradeoff_from.rig_facts(rig)[1] == 8  # the premise: an 8-LED dome
    out = tmp_path / "o"
    argv = ["bench", "tradeoff", "--from", str(ACQ), "--out", str(out), "--rig", str(rig)]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    assert r.exit_code == 0, r.output
    text = " ".join((out / "summary.md").read_text(encoding="utf-8").split())
    two = text[text.index("- **Normals within 2°**") :].split(" - **")[0]
    assert "from **9 lights** of this acquisition, more than the 8 LEDs of" in two, two
    assert "`rti-rig run" not in two, two
    three = text[text.index("- **Normals within 3°**") :].split(" - **")[0]
    assert "--lights 6`" in three, three
    assert "has 8 LEDs, fewer than this acquisition's lights" in text, text
    # without --rig: the commands as before (RIG), no word of a dome's LEDs
    r = CliRunner().invoke(app, argv[:4], terminal_width=400)
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert "--lights 9`" in text and "LEDs of" not in text, text
