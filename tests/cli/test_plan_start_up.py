"""`rti-rig plan` on an arm loads only what planning needs.

Start-up is most of a short plan's time through the front door (docs/adaptive.md,
"plan_cli_time"): scipy.optimize (0.3 s to import) serves only a dome's or k-means' assignment,
scipy.ndimage only a RAW decode, the drivers and the TIFF writer only a session. A module-level
import of any of them would put that time back on every arm plan; these tests would see it.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

NOT_FOR_AN_ARM_PLAN = (
    "scipy",
    "tifffile",
    "dynamixel_sdk",
    "serial",
    "matplotlib",
    "onnxruntime",
    "sklearn",
    "rti_rig.drivers.dynamixel.arm",
    "rti_rig.drivers.led_dome.driver",
)

SCRIPT = """
import json, sys
from rti_rig.cli import main
sys.argv = ["rti-rig", *json.loads(sys.argv[1])]
try:
    main()
except SystemExit as exc:
    assert not exc.code, exc.code
print("LOADED " + json.dumps(sorted(sys.modules)))
"""


def _modules_after(args: list[str]) -> set[str]:
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT, json.dumps(args)],
        capture_output=True,
        text=True,
        cwd=REPO,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    line = next(x for x in done.stdout.splitlines() if x.startswith("LOADED "))
    return set(json.loads(line[len("LOADED ") :]))


def _loaded(modules: set[str], name: str) -> bool:
    return name in modules or any(m.startswith(name + ".") for m in modules)


@pytest.mark.e2e
def test_an_arm_plan_from_a_preview_loads_no_scipy_driver_or_tiff_writer(tmp_path) -> None:
    import cv2
    import numpy as np

    from rti_rig.core.lp_format import read_lp

    png = tmp_path / "preview.png"
    ramp = np.linspace(2000, 60000, 48 * 64).reshape(48, 64).astype(np.uint16)
    cv2.imwrite(str(png), ramp)
    out = tmp_path / "plan.lp"
    rig = REPO / "rig_configs" / "simulated_arm.toml"  # servo settings: move-time order
    args = ["plan", str(png), "--rig", str(rig), "--lights", "12", "--method", "optimal"]
    modules = _modules_after([*args, "--preview-light", "30,50", "--out", str(out)])
    assert len(read_lp(out)) == 12
    assert "rti_rig.planner.arm_order" in modules  # the servos' order ran
    loaded = [name for name in NOT_FOR_AN_ARM_PLAN if _loaded(modules, name)]
    assert loaded == []


@pytest.mark.e2e
@pytest.mark.parametrize(("lights", "needs_solver"), [(12, True), (48, False)])
def test_a_dome_plan_loads_the_assignment_solver_when_its_layouts_need_it(
    tmp_path, lights, needs_solver
) -> None:
    """The other side: a dome's homogeneous layouts of fewer lights than LEDs are matched to
    its LEDs by scipy's solver, loaded then; a plan of all 48 LEDs matches nothing."""
    out = tmp_path / "plan.lp"
    rig = REPO / "rig_configs" / "simulated_dome.toml"
    args = ["plan", "--rig", str(rig), "--lights", str(lights), "--method", "optimal"]
    modules = _modules_after([*args, "--out", str(out)])
    assert out.is_file()
    assert ("scipy.optimize" in modules) == needs_solver
