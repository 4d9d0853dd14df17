"""`python -m benchmarks.planning_time --cli`: the whole `rti-rig plan` process, timed."""

from __future__ import annotations

import shlex

import pytest

from benchmarks import planning_time


@pytest.mark.slow
def test_cli_case_times_a_fresh_plan_process_and_compares_the_plans(tmp_path) -> None:
    """One case (the shipped dome at 24 lights), this checkout against itself: a row per
    command with its wall, CPU and "planned in" seconds, and the plans found identical."""
    md = planning_time.cli_main(
        ["--cli", "--repeats", "1", "--cases", "2", "--against",
         shlex.join(planning_time.default_command()), "--against-label", "itself"]
    )  # fmt: skip
    rows = [line for line in md.splitlines() if line.startswith("| shipped 48-LED dome | 24 |")]
    assert [r.split(" | ")[2] for r in rows] == ["this", "itself"]
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        wall, cpu, planned = (float(c) for c in cells[3:6])
        assert 0 < planned < wall and cpu > 0
        assert cells[6] == "yes"


def test_a_run_plan_of_the_front_door_reads_its_own_report(tmp_path) -> None:
    preview, _ = planning_time.cli_inputs(tmp_path)
    rig = planning_time.REPO / "rig_configs" / "virtual_arm.toml"
    run = planning_time.run_plan_cli(
        planning_time.default_command(), rig, 9, preview, tmp_path / "plan.lp"
    )
    assert run.planned_s > 0 and run.wall_s > run.planned_s
    assert len(run.plan_sha256) == 64 and (tmp_path / "plan.lp").is_file()


@pytest.mark.parametrize(
    ("report", "seconds"),
    [
        ("expected RMS normal error 2.1°\nplanned in 0.24 s\n", 0.24),
        (
            "planned in 1.10 s (0.85 s choosing the lights, 0.25 s ordering the arm's stops)",
            0.85,
        ),
    ],
    ids=["dome", "arm"],
)
def test_planned_in_is_the_search_alone_as_the_table_says(report: str, seconds: float) -> None:
    """The table's "planned in" is the search, not the arm's order: an arm plan's report says
    the whole and its parts, and the whole had been read."""
    assert planning_time.planned_seconds(report) == seconds
