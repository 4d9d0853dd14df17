"""`rti-rig plan` orders a simulated arm's lights by the time the arm really takes.

Why: virtual_arm.toml (no ``[arm.dynamixel]``) was ordered nearest neighbour by angle, which
ignores that the simulated arm's azimuth cannot wrap past ±180°: a 12-light plan had one 6.0 s
move from -170° to 157.6° the long way round, and its moves took 19.6 s where 14.8 s do.
The plan is timed on the simulated arm itself (the world), not on the planner's model.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config, rig_geometry
from rti_rig.cli import app
from rti_rig.core.clock import VirtualClock
from rti_rig.core.lp_format import read_lp
from rti_rig.planner.uniform import order_nearest_neighbour
from rti_rig.simulator.sim_lights import LightState, SimulatedArm

runner = CliRunner()


def _moves_s(config: Path, dirs: np.ndarray) -> list[float]:
    """Each move's duration on the simulated arm the config describes, from its park pose."""
    loaded = load_rig_config(config)
    arm = loaded.config.arm
    assert arm is not None
    geometry = rig_geometry(loaded)
    clock = VirtualClock()
    sim = SimulatedArm(
        geometry,  # type: ignore[arg-type]
        LightState(),
        clock,
        speed_deg_s=arm.speed_deg_s,
        acceleration_deg_s2=arm.acceleration_deg_s2,
        resolution_deg=arm.resolution_deg,
    )
    sim.connect()
    out = []
    for d in dirs:
        t0 = clock.now()
        sim.move_to(d)
        out.append(clock.now() - t0)
    return out


def test_plan_on_a_simulated_arm_never_takes_the_long_way_round(tmp_path: Path) -> None:
    config = CONFIGS / "virtual_arm.toml"
    plan = tmp_path / "plan.lp"
    args = ["plan", "--rig", str(config), "--lights", "12", "--out", str(plan)]
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    dirs = np.array([e.direction for e in read_lp(plan)])
    assert len(dirs) == 12
    planned = _moves_s(config, dirs)
    park = rig_geometry(load_rig_config(config)).park_direction
    nearest = _moves_s(config, dirs[order_nearest_neighbour(dirs, park)])
    # the angle-nearest order of these lights swings the azimuth joint across its stop
    # (the old plan: one 6.0 s move, 19.6 s in all)
    assert max(nearest) > 5.0
    assert max(planned) < 3.0, planned
    assert sum(planned) < 0.9 * sum(nearest), (sum(planned), sum(nearest))
