"""``benchmarks.adaptive`` refuses a draw count its paired verdicts cannot use, before it runs
anything (it crashed in the paired test after minutes of simulation)."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks import adaptive


@pytest.mark.parametrize("args", [["--sim-draws", "1"], ["--real-draws", "1"]])
def test_one_draw_is_refused_up_front(args: list[str], capsys) -> None:
    with pytest.raises(SystemExit) as caught:
        adaptive.main(args)
    assert caught.value.code == 2
    assert "at least 2" in capsys.readouterr().err


@pytest.fixture
def planner_constants(monkeypatch: pytest.MonkeyPatch):  # type: ignore[no-untyped-def]
    """The constants the options set, restored after the test."""
    import rti_rig.planner.adaptive as planner

    for name in (
        "FITTED_DESIGN",
        "FITTED_MARGIN",
        "SIM_MARGIN",
        "FITTED_SEED_FLOORS",
        "DESIGN_FLOORS",
        "DESIGN_DEFAULT_FLOOR",
        "START_ABOVE_FLOOR",
    ):
        monkeypatch.setattr(planner, name, getattr(planner, name))
    monkeypatch.setitem(adaptive.START, "start", adaptive.START["start"])
    return planner


def test_without_options_the_planner_is_left_as_it_ships(planner_constants) -> None:
    planner = planner_constants
    before = (planner.FITTED_SEED_FLOORS, planner.FITTED_MARGIN, planner.DESIGN_DEFAULT_FLOOR)
    adaptive.configure_planner(adaptive.build_parser().parse_args([]))
    after = (planner.FITTED_SEED_FLOORS, planner.FITTED_MARGIN, planner.DESIGN_DEFAULT_FLOOR)
    assert after == before
    assert planner.FITTED_SEED_FLOORS == ()  # what ships


def test_the_variants_options_set_the_planner_s_constants(planner_constants) -> None:
    planner = planner_constants
    args = adaptive.build_parser().parse_args(
        [
            "--fitted-seeds",
            "none",
            "--fitted-margin",
            "0.05",
            "--sim-margin",
            "0.2",
            "--floors",
            "0,10,15,20,30",
            "--default-floor",
            "15",
        ]
    )
    adaptive.configure_planner(args)
    assert planner.FITTED_SEED_FLOORS == ()
    assert planner.FITTED_MARGIN == 0.05 and planner.SIM_MARGIN == 0.2
    assert planner.DESIGN_FLOORS == (0.0, 10.0, 15.0, 20.0, 30.0)
    assert planner.DESIGN_DEFAULT_FLOOR == 15.0
    adaptive.configure_planner(adaptive.build_parser().parse_args(["--fitted-seeds", "5,15"]))
    assert planner.FITTED_SEED_FLOORS == (5.0, 15.0)


def test_a_hedged_start_is_built_for_the_default_floor_the_options_set(
    planner_constants,
) -> None:
    """``--default-floor 20 --start hedge-10``: 4 lights of the 20° layout (the start is read
    after the floor is set)."""
    from rti_rig.core.geometry import fibonacci_cap
    from rti_rig.core.rig_geometry import DomeGeometry
    from rti_rig.planner.uniform import select_uniform_leds

    args = adaptive.build_parser().parse_args(["--default-floor", "20", "--start", "hedge-10"])
    adaptive.configure_planner(args)
    dome = DomeGeometry(fibonacci_cap(120, 3.0), tuple(f"l{i}" for i in range(120)))
    start = adaptive.START["start"](dome, 4, 9)
    assert len(start) == 4 and set(start) <= set(select_uniform_leds(dome, 9, 20.0).tolist())


def test_relight_basis_sets_what_the_chooser_scores_designs_by(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``--relight-basis hsh1``: every relight decision scores its designs by that basis (the
    chooser's name for the function is replaced; nothing of what ships changes without it)."""
    import rti_rig.planner.adaptive as planner

    monkeypatch.setattr(planner, "relight_basis", planner.relight_basis)
    adaptive.configure_planner(adaptive.build_parser().parse_args([]))
    assert planner.relight_basis(9) == "ptm"  # the richest basis 9 lights determine
    adaptive.configure_planner(adaptive.build_parser().parse_args(["--relight-basis", "hsh1"]))
    assert planner.relight_basis(9) == planner.relight_basis(18) == "hsh1"


def test_start_above_floor_sets_which_objectives_start_above_it(planner_constants) -> None:
    """``--start-above-floor normals,relight`` (the variant measured against what ships): the
    normals objective's start then keeps above START_FLOOR_DEG too; ``none`` for neither; an
    unknown objective is refused by name."""
    from rti_rig.app.usecases.adaptive import dome_start
    from rti_rig.core.geometry import fibonacci_cap
    from rti_rig.core.rig_geometry import DomeGeometry

    planner = planner_constants
    assert planner.START_ABOVE_FLOOR == ("relight",)  # what ships
    dome = DomeGeometry(fibonacci_cap(240, 0.0), tuple(f"l{i}" for i in range(240)))
    el = np.degrees(np.arcsin(dome.directions[:, 2]))
    assert el[dome_start(dome, 4, 9, "normals")].min() < planner.START_FLOOR_DEG
    adaptive.configure_planner(
        adaptive.build_parser().parse_args(["--start-above-floor", "normals,relight"])
    )
    assert planner.START_ABOVE_FLOOR == ("normals", "relight")
    assert el[dome_start(dome, 4, 9, "normals")].min() >= planner.START_FLOOR_DEG
    adaptive.configure_planner(adaptive.build_parser().parse_args(["--start-above-floor", "none"]))
    assert planner.START_ABOVE_FLOOR == ()
    assert el[dome_start(dome, 4, 9, "relight")].min() < planner.START_FLOOR_DEG
    with pytest.raises(SystemExit, match="unknown objective gloss"):
        adaptive.configure_planner(
            adaptive.build_parser().parse_args(["--start-above-floor", "gloss"])
        )


def test_relight_margin_sets_the_relight_objective_s_hysteresis(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``--relight-margin 0.25``: a relight decision leaves its design for one simulated 0.3 dB
    better (kept at the 0.5 dB that ships); absent, the constant is left as it ships."""
    import rti_rig.planner.adaptive_relight as relight

    monkeypatch.setattr(relight, "RELIGHT_MARGIN_DB", relight.RELIGHT_MARGIN_DB)
    adaptive.configure_planner(adaptive.build_parser().parse_args([]))
    assert relight.RELIGHT_MARGIN_DB == 0.5
    assert relight.pick_floor({10.0: 30.0, 20.0: 30.3}, keep_floor=10.0) == 10.0
    adaptive.configure_planner(adaptive.build_parser().parse_args(["--relight-margin", "0.25"]))
    assert relight.RELIGHT_MARGIN_DB == 0.25
    assert relight.pick_floor({10.0: 30.0, 20.0: 30.3}, keep_floor=10.0) == 20.0
