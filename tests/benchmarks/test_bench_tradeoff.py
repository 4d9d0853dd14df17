"""The speed/accuracy benchmark runs end to end and its numbers mean what they say."""

from __future__ import annotations

import math
import shlex
from pathlib import Path

import numpy as np
import pytest

from benchmarks.tradeoff import (
    DOME_CONFIG,
    TradeoffSettings,
    per_light_s,
    plot,
    render_scene_data,
    run_scene,
    score_plan,
    shipped_rig,
    summarise,
    write_csv,
)

TINY = TradeoffSettings(
    scenes=("painting",),
    size_px=24,
    counts=(3, 8),
    ground_truth_lights=60,
    held_out_lights=8,
    candidates=40,
    floors_deg=(0.0, 20.0),
)


@pytest.fixture(scope="module")
def rows():  # type: ignore[no-untyped-def]
    data = render_scene_data("painting", TINY)
    return run_scene(data, TINY, progress=lambda _m: None)


@pytest.mark.slow
def test_every_plan_is_scored_and_timed(rows) -> None:  # type: ignore[no-untyped-def]
    kinds = {(r.method, r.objective, r.floor_deg) for r in rows}
    assert ("kmeans", "normals", 0.0) in kinds and ("optimal", "relight", 0.0) in kinds
    assert ("uniform", "-", 20.0) in kinds
    for r in rows:
        assert math.isfinite(r.normal_mean_deg) and 0 <= r.normal_mean_deg <= 180
        assert r.dome_time_s == pytest.approx(r.n * per_light_s(shipped_rig(DOME_CONFIG)))
        assert r.arm_time_s > r.dome_time_s  # the arm also moves between lights
        assert math.isfinite(r.relight_psnr_db)


def test_more_lights_help_the_homogeneous_layout() -> None:
    """Many lights beat few. Compared at 3 and 16: the orthogonal triad of 3 lights (0.82° on
    this 24-px painting) beats the even spiral of 8 (0.86°), so 8 showed nothing about the
    count."""
    from rti_rig.core.rig_geometry import DomeGeometry
    from rti_rig.planner.uniform import select_uniform_leds

    data = render_scene_data("painting", TINY)
    dome = DomeGeometry(data.candidate_dirs, tuple(f"c{i}" for i in range(TINY.candidates)))
    error = {n: score_plan(data, select_uniform_leds(dome, n))[0] for n in (3, 16)}
    assert error[16] < 0.6 * error[3], error


def test_scores_see_a_bad_plan() -> None:
    """Three nearly coplanar lights must score far worse than three well-spread ones."""
    data = render_scene_data("painting", TINY)
    el = np.degrees(np.arcsin(data.candidate_dirs[:, 2]))
    high = np.argsort(-el)[:3]  # three lights around the zenith: nearly coplanar
    az = np.degrees(np.arctan2(data.candidate_dirs[:, 1], data.candidate_dirs[:, 0])) % 360
    spread = [
        int(np.argmin(np.abs(el - 45) + np.abs(((az - a + 180) % 360) - 180) / 4))
        for a in (0, 120, 240)
    ]
    bad, good = score_plan(data, high), score_plan(data, np.array(spread))
    assert bad[0] > 3 * good[0]


@pytest.mark.slow
def test_outputs(rows, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    csv_path = write_csv(rows, tmp_path / "results.csv")
    assert csv_path.read_text().count("\n") == len(rows) + 1
    pngs = plot(rows, tmp_path)
    assert len(pngs) == 6 and all(p.stat().st_size > 1000 for p in pngs)
    text = summarise(rows, TINY, 1.0, "test")
    assert "## painting" in text and "What the numbers say" in text


def test_bench_writes_nothing_unless_asked(  # type: ignore[no-untyped-def]
    rows, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`bench tradeoff --quick` must never replace the committed docs/tradeoff results."""
    from typer.testing import CliRunner

    import benchmarks.tradeoff as tradeoff
    from rti_rig.cli import app

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(
        tradeoff, "run_tradeoff", lambda settings, progress, done: done.extend(rows) or rows
    )
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--quick"])
    assert r.exit_code == 0, r.output
    assert list(tmp_path.rglob("*")) == []
    assert "nothing written" in r.output
    # the way to keep them is the command with a folder not there yet ("give --out DIR",
    # pasted, wrote into a folder named DIR): it writes there
    said = " ".join(r.output.split())
    # ... and it ends the output: a ")" after it had been read as the folder's last letter
    command = said.split("run it with --out: ", 1)[1]
    assert command == "rti-rig bench tradeoff --quick --out tradeoff", command
    again = CliRunner().invoke(app, shlex.split(command)[1:])
    assert again.exit_code == 0, again.output
    assert (tmp_path / "tradeoff" / "results.csv").is_file()
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--quick", "--out", "my res"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "my res" / "results.csv").is_file()
    # the command in the summary pastes back as run (the folder had been written bare)
    summary = (tmp_path / "my res" / "summary.md").read_text(encoding="utf-8")
    assert "`rti-rig bench tradeoff --quick --out 'my res'`" in summary, summary
    # it says against what truth it scores and what its session time counts, the shipped
    # dome's own figure (it had said neither: the time read as the whole session a user waits)
    said = " ".join(summary.split())
    assert "the mean angle to the scene's true normals" in said, said
    assert "against noise-free renders under the held-out lights" in said, said
    per_light = per_light_s(shipped_rig(DOME_CONFIG))
    assert (
        'is the rig time `rti-rig run` reports ("Session time on the real rig") for the '
        f"plan's lights: on rig_configs/simulated_dome.toml {per_light:.2f} s a light" in said
    ), said
    assert "It leaves out connecting, the preview, planning" in said, said


def test_fault_campaign_writes_its_report_only_when_asked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import sys

    import benchmarks.fault_campaign as fc

    monkeypatch.setattr(fc, "REPO", tmp_path)
    monkeypatch.setattr(sys, "argv", ["fault_campaign", "--sessions", "0"])
    fc.main()
    assert not (tmp_path / "docs").exists()
    monkeypatch.setattr(sys, "argv", ["fault_campaign", "--sessions", "0", "--write"])
    fc.main()
    assert (tmp_path / "docs" / "reliability.md").is_file()


def test_fault_campaign_writes_only_its_own_section(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """docs/reliability.md holds other sections between the campaign's and the dome
    firmwares' ("Emulators on a pty under CPU load"): a --write had deleted them, keeping
    only what followed the firmwares' marker."""
    import sys

    import benchmarks.fault_campaign as fc

    docs = tmp_path / "docs" / "reliability.md"
    docs.parent.mkdir()
    docs.write_text(
        "<!-- BEGIN fault_campaign -->\nold figures\n<!-- END fault_campaign -->\n\n"
        "## Emulators on a pty under CPU load\n\nkept\n\n"
        "<!-- BEGIN firmware_faults -->\nfirmware figures\n<!-- END firmware_faults -->\n"
    )
    monkeypatch.setattr(fc, "REPO", tmp_path)
    monkeypatch.setattr(sys, "argv", ["fault_campaign", "--sessions", "0", "--write"])
    fc.main()
    text = docs.read_text()
    assert "old figures" not in text and "# Reliability: fault campaign" in text
    assert "## Emulators on a pty under CPU load\n\nkept\n" in text
    assert "firmware figures" in text


def _row(method: str, objective: str, n: int, floor: float, deg: float, db: float):  # type: ignore[no-untyped-def]
    from benchmarks.tradeoff import Row

    return Row(
        "painting", method, objective, n, floor, deg, deg, 1.0, "ptm", db, 0.9, 1.0, 1.0, 0.0
    )


def test_the_verdicts_compare_with_naive_uniform_when_floor_0_is_also_the_best() -> None:
    """With floor 0° the scene's best, the naive series is named "uniform (floor 0°, also the
    best here)"; the verdicts had looked for "uniform", compared nothing, and said "never
    worse" of an optimal plan 4 dB worse in their own table (bench tradeoff --quick,
    painting). Here optimal loses on relighting at both N and k-means beats uniform at N = 8."""
    from benchmarks.tradeoff import _series, _verdicts

    rows = []
    for n in (6, 8):
        rows += [
            _row("uniform", "normals", n, 0.0, 1.0, 33.5),
            _row("uniform", "normals", n, 20.0, 2.0, 30.0),  # a worse floor: 0° is the best
            _row("optimal", "normals", n, 0.0, 0.9, 33.0),
            _row("optimal", "relight", n, 0.0, 1.2, 29.5),
            _row("kmeans", "normals", n, 0.0, 1.1 if n == 6 else 0.95, 30.0),
        ]
    series = _series(rows, "painting")
    assert "uniform (floor 0°, also the best here)" in series and "uniform" not in series
    text = "\n".join(_verdicts("painting", series, [6, 8]))
    assert "beats naive uniform on normals only at N = 8" in text
    assert "optimal/relight vs uniform (floor 0°, also the best here) on relight_psnr_db: " in text
    assert "worse at N = 6, 8" in text
    assert (
        "optimal/normals vs uniform (floor 0°, also the best here) on normal_mean_deg: never worse"
        in text
    )
    assert "mean gain at N ≤ 10: -4.00 dB" in text


def test_a_verdict_with_nothing_to_compare_says_so() -> None:
    from benchmarks.tradeoff import _verdicts

    text = "\n".join(_verdicts("painting", {}, [6, 8]))
    assert "never" not in text
    assert "was not compared with naive uniform" in text and "not compared (no N with both)" in text


def test_the_arm_is_timed_in_the_order_run_gives_a_simulated_arm() -> None:
    """``rti-rig run`` orders a simulated arm's stops by move time (compose.arm_order_for),
    not by angle: the benchmark's arm time must be that order's, never the nearest-neighbour
    order's when that one is slower (stops either side of ±180°, which the azimuth cannot
    cross: nearest by angle, a whole turn apart for the arm)."""
    from benchmarks.tradeoff import ARM_CONFIG, session_times, timed_arm
    from rti_rig.core.geometry import direction_from_az_el
    from rti_rig.planner.uniform import order_nearest_neighbour

    dirs = np.array(
        [direction_from_az_el(az, 30.0) for az in (170.0, -170.0, 100.0, -100.0, 30.0, -30.0)]
    )
    rig = shipped_rig(ARM_CONFIG)
    # the same arm, lamp and lit time as session_times (virtual_arm.toml's), in the other
    # order: its figures had been typed in (1.41 s lit where the config gives 1.35 s + two
    # 0.02 s lamp switches), so the two differed by more than the order
    arm, geometry, clock, lit_s = timed_arm(rig)
    arm.lamp(False)
    for i in order_nearest_neighbour(dirs, geometry.park_direction):
        arm.move_to(dirs[i])
        arm.lamp(True)
        clock.sleep(lit_s)
        arm.lamp(False)
    arm.lamp(False)
    arm.park()
    _, timed = session_times(dirs, shipped_rig(DOME_CONFIG), rig)
    # nearest by angle: 30, -30, -100, -170, then 170 a whole turn away (24.2 s in all, the
    # move-time order 23.2 s)
    assert timed < clock.now() - 0.5, (timed, clock.now())


def test_retime_arm_keeps_the_scores_and_remeasures_the_arm_column(rows, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """``python -m benchmarks.tradeoff --retime-arm``: the plans made again give the arm times
    of the run, every other column of results.csv kept as written (a run from before a
    column, file_model, keeps its columns)."""
    import csv

    from benchmarks.tradeoff import main, retime_arm

    write_csv(rows, tmp_path / "results.csv")
    again = retime_arm(tmp_path, TINY, progress=lambda _m: None)
    assert [r.arm_time_s for r in again] == pytest.approx([r.arm_time_s for r in rows])
    assert [r.normal_mean_deg for r in again] == pytest.approx([r.normal_mean_deg for r in rows])
    # an arm column off by 0.2 s a light, as the run before 2026-12-02 wrote it, and a file
    # without the newest columns: the arm column is measured again, the columns kept
    old = tmp_path / "old"
    old.mkdir()
    with (tmp_path / "results.csv").open(newline="") as f:
        recorded = list(csv.DictReader(f))
    columns = [c for c in recorded[0] if c not in ("file_model", "file_psnr_db", "lights")]
    with (old / "results.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for r in recorded:
            w.writerow({**r, "arm_time_s": float(r["arm_time_s"]) - 0.2 * int(r["n"])})
    main(["--retime-arm", str(old)], TINY)
    with (old / "results.csv").open(newline="") as f:
        rewritten = list(csv.DictReader(f))
    # the run's columns kept, with the plans' lights it had not said (each plan scored again:
    # the same scores, the same plan)
    assert list(rewritten[0]) == [*columns, "lights"]
    assert [r["lights"] for r in rewritten] == [r.lights for r in rows]
    assert [float(r["arm_time_s"]) for r in rewritten] == pytest.approx(
        [r.arm_time_s for r in rows]
    )
    assert [r["normal_mean_deg"] for r in rewritten] == [r["normal_mean_deg"] for r in recorded]


def test_retime_arm_measures_again_a_row_whose_plan_changed(  # type: ignore[no-untyped-def]
    rows, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A row the run measured on other lights than today's plan for it (a planner changed
    since) is measured again whole and said by name: --retime-arm had kept its scores beside
    the new plan's arm time, a row of two plans (docs/research/tradeoff.md's 14 rows). The
    same for a run from before the lights column whose scores are not today's plan's."""
    import csv

    from benchmarks.tradeoff import main

    kmeans8 = next(i for i, r in enumerate(rows) if r.method == "kmeans" and r.n == 8)
    for name, tamper in (
        ("lights", {"lights": "0 1 2 3 4 5 6 7", "normal_mean_deg": "42.0"}),
        ("before", {"normal_mean_deg": "42.0"}),
    ):
        folder = tmp_path / name
        write_csv(rows, folder / "results.csv")
        with (folder / "results.csv").open(newline="") as f:
            recorded = list(csv.DictReader(f))
        recorded[kmeans8].update(tamper)
        columns = [c for c in recorded[0] if name == "lights" or c != "lights"]
        with (folder / "results.csv").open("w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
            w.writeheader()
            w.writerows(recorded)
        # the second a stopped run's partial table, which must stay one
        partial = "Stopped (Ctrl-C): 1 of 2 scenes measured whole (painting); not measured: x"
        first = f"**{partial}**\n\n" if name == "before" else ""
        (folder / "summary.md").write_text(
            first + "Measured with `rti-rig bench tradeoff` in 5 s.\n"
        )
        main(["--retime-arm", str(folder)], TINY)
        said = " ".join(capsys.readouterr().out.split())
        # its tables are written again from the rows as they now are (they had the old scores)
        assert f"{folder / 'summary.md'} rewritten: 1 row(s) measured again whole" in said, said
        summary = (folder / "summary.md").read_text()
        assert "## painting" in summary and "42.00" not in summary, summary
        assert "Measured with `rti-rig bench tradeoff` in 5 s" in summary, summary
        assert (f"**{partial}**" in summary) == (name == "before"), summary
        assert "1 row(s) whose plan is not the one the run measured" in said, said
        assert "were measured again whole, scores and times: kmeans/normals N=8 floor 0°" in said
        with (folder / "results.csv").open(newline="") as f:
            rewritten = list(csv.DictReader(f))
        assert float(rewritten[kmeans8]["normal_mean_deg"]) == pytest.approx(
            rows[kmeans8].normal_mean_deg
        )
        assert rewritten[kmeans8]["lights"] == rows[kmeans8].lights
        assert [float(r["arm_time_s"]) for r in rewritten] == pytest.approx(
            [r.arm_time_s for r in rows]
        )


def test_a_stopped_run_keeps_and_says_the_scenes_measured_whole(  # type: ignore[no-untyped-def]
    rows, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A Ctrl-C in the second scene of `bench tradeoff --quick --out` keeps the first scene's
    table in --out, says it is partial (and which scenes it lacks), exit 130: it had said only
    "stopped (Ctrl-C)", every scene measured lost and the --out folder left empty."""
    from types import SimpleNamespace

    from typer.testing import CliRunner

    import benchmarks.tradeoff as tradeoff
    from rti_rig.cli import app

    def scene(data, settings, progress):  # type: ignore[no-untyped-def]
        if data.name != "painting":
            raise KeyboardInterrupt
        return rows

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(tradeoff, "render_scene_data", lambda name, s: SimpleNamespace(name=name))
    monkeypatch.setattr(tradeoff, "run_scene", scene)
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--quick", "--out", "part"])
    assert r.exit_code == 130, r.output
    said = " ".join(r.output.split())
    stopped = "Stopped (Ctrl-C): 1 of 4 scenes measured whole (painting); not measured: coin, "
    assert stopped + "tilted, industrial; the partial results are in part" in said, said
    summary = (tmp_path / "part" / "summary.md").read_text(encoding="utf-8")
    assert stopped in summary and "## painting" in summary and "## coin" not in summary
    assert "Scenes painting at" in summary, summary
    written = (tmp_path / "part" / "results.csv").read_text(encoding="utf-8")
    assert written.count("\n") == len(rows) + 1
    # a folder of earlier results, given with --force: kept as they were, not replaced by a part
    (tmp_path / "part" / "summary.md").write_text("a whole run's\n", encoding="utf-8")
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--quick", "--out", "part", "--force"])
    assert r.exit_code == 130, r.output
    assert "the results already in part are left as they were" in " ".join(r.output.split())
    assert (tmp_path / "part" / "summary.md").read_text(encoding="utf-8") == "a whole run's\n"
    # stopped in the first scene: nothing measured whole, nothing written, said so
    monkeypatch.setattr(
        tradeoff, "run_scene", lambda *_a: scene(SimpleNamespace(name="x"), *_a[1:])
    )
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--quick"])
    assert r.exit_code == 130, r.output
    assert "Stopped (Ctrl-C) before a scene was measured whole: nothing written" in r.output
    # with an --out the run made: not left behind, empty
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--quick", "--out", "none"])
    assert r.exit_code == 130, r.output
    assert "nothing written to none" in " ".join(r.output.split())
    assert not (tmp_path / "none").exists()


def test_retime_arm_refuses_by_name_what_is_not_a_full_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A --quick run's folder (its plans are made on 120 candidates, not the full run's 240:
    every row would have been timed on another plan) and a folder without results.csv are
    refused by name, exit 2, before anything is rendered (the second had been a traceback)."""
    from benchmarks.tradeoff import main

    (tmp_path / "results.csv").write_text("scene,method\n", encoding="utf-8")
    (tmp_path / "summary.md").write_text(
        "Measured with `rti-rig bench tradeoff --quick --out q` in 40 s.\n", encoding="utf-8"
    )
    for folder, words in (
        (tmp_path, "is not a full simulated run (its summary.md says a --quick one)"),
        (tmp_path / "none", "results.csv: No such file or directory"),
    ):
        with pytest.raises(SystemExit) as stop:
            main(["--retime-arm", str(folder)])
        assert stop.value.code == 2
        said = " ".join(capsys.readouterr().err.split())
        assert f"{folder}" in said and words in said, said
