"""What `pip install .` puts in a user's site-packages, and what importing the runtime costs.

The product installs as one package, ``rti_rig`` (its sub-packages drivers, planner, simulator
and rig_configs mapped from the top-level folders of the same names), so nothing else of ours
can collide with a user's ``planner`` or ``drivers``; and the controller can be imported (by a
notebook, a test, another program) without loading a single device library.
"""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BARE = {"drivers", "planner", "simulator", "rig_configs"}
DEVICE_LIBRARIES = ("dynamixel_sdk", "serial", "cv2", "rawpy", "gphoto2")


def python_files() -> list[Path]:
    folders = ["rti_rig", "drivers", "planner", "simulator", "rig_configs", "tests", "benchmarks"]
    return [p for f in folders for p in (REPO / f).rglob("*.py") if "__pycache__" not in p.parts]


def test_no_module_imports_our_folders_by_their_bare_names():
    """`import planner` works in a checkout but not once installed: always `rti_rig.planner`."""
    offenders = []
    for path in python_files():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for name in names:
                if name.split(".")[0] in BARE:
                    offenders.append(f"{path.relative_to(REPO)}:{node.lineno}: {name}")
    assert offenders == []


@pytest.mark.parametrize(
    "module",
    ["rti_rig.runtime.controller", "rti_rig.runtime.session", "rti_rig.core.lp_format"],
)
def test_importing_the_runtime_loads_no_device_library(module):
    code = (
        f"import sys, {module}; "
        f"print(','.join(m for m in {DEVICE_LIBRARIES!r} if m in sys.modules))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    ).stdout.strip()
    assert loaded == ""


def test_the_check_has_teeth():
    """The same probe sees a device library when one is imported (so an empty list means absent)."""
    code = (
        "import sys, rti_rig.drivers.led_dome.transport; "
        f"print(','.join(m for m in {DEVICE_LIBRARIES!r} if m in sys.modules))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    ).stdout.strip()
    assert "serial" in loaded.split(",")


@pytest.mark.slow
def test_the_wheel_holds_one_top_level_package(tmp_path):
    # built from a copy: an in-tree build would leave a build/ folder in the checkout
    source = tmp_path / "src"
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info")
    for folder in ("rti_rig", "drivers", "planner", "simulator", "rig_configs"):
        shutil.copytree(REPO / folder, source / folder, ignore=ignore)
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(REPO / name, source / name)
    wheels = tmp_path / "wheels"
    built = subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "-q",
            "--no-deps",
            "--no-build-isolation",
            "-w",
            str(wheels),
            str(source),
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert built.returncode == 0, built.stderr
    (wheel,) = wheels.glob("rti_rig-*.whl")
    with zipfile.ZipFile(wheel) as zf:
        names = zf.namelist()
        (top_level,) = [n for n in names if n.endswith(".dist-info/top_level.txt")]
        assert zf.read(top_level).decode().split() == ["rti_rig"]
    tops = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert tops == {"rti_rig"}
    # the mapped folders are inside it, shipped configs included
    for inside in (
        "rti_rig/drivers/led_dome/driver.py",
        "rti_rig/planner/make_plan.py",
        "rti_rig/simulator/scenes.py",
        "rti_rig/rig_configs/simulated_dome.toml",
        "rti_rig/rig_configs/example_dome_48.lp",
        "rti_rig/core/geometry.py",
    ):
        assert inside in names


DASK_MODULES = ("dask", "distributed")


@pytest.mark.parametrize(
    "module",
    [
        "rti_rig",
        "rti_rig.cli",
        "rti_rig.app.usecases.fit",
        "rti_rig.app.usecases.fit_dask",
        "rti_rig.app.usecases.scheduler_probe",
        "rti_rig.reconstruct.lazy_stack",
    ],
)
def test_dask_is_imported_only_when_a_fit_runs_on_it(module):
    """The plain fit, the CLI and even the Dask modules themselves load neither dask nor
    distributed until ``--scheduler`` makes a lazy stack or a client."""
    code = f"import sys, {module}; print(','.join(m for m in {DASK_MODULES!r} if m in sys.modules))"
    loaded = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    ).stdout.strip()
    assert loaded == ""


def test_the_dask_check_has_teeth(tmp_path):
    """Making a lazy stack does load dask (so an empty list above means absent)."""
    code = (
        "import sys, numpy as np\n"
        "from rti_rig.reconstruct.lazy_stack import StackSource, lazy_stack\n"
        "lazy_stack(StackSource(('a.tif',), (4, 4, 1), True, 1.0, None), 2)\n"
        f"print(','.join(m for m in {DASK_MODULES!r} if m in sys.modules))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
        cwd=tmp_path,
    ).stdout.strip()
    assert "dask" in loaded.split(",")
