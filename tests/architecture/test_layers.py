"""The layer contract (pyproject's [tool.importlinter]) holds, and it bites when broken.

import-linter reads a package from its folder, but rti_rig's sub-packages live in top-level
folders mapped by setuptools' package-dir; so the test lays the installed tree out in a temporary
folder exactly as ``pip install .`` would (from the same mapping) and checks that copy.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PYPROJECT = REPO / "pyproject.toml"


def installed_layout(dest: Path) -> Path:
    """Copy the sources into ``dest`` as the installed package tree (package-dir mapping)."""
    setup = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["tool"]["setuptools"]
    mapping: dict[str, str] = setup["package-dir"]
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    for package, folder in sorted(mapping.items(), key=lambda kv: kv[0].count(".")):
        target = dest.joinpath(*package.split("."))
        shutil.copytree(REPO / folder, target, ignore=ignore, dirs_exist_ok=True)
    return dest


def lint_imports(tree: Path, config: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(tree)}
    code = "import sys; from importlinter.cli import lint_imports_command; lint_imports_command()"
    return subprocess.run(
        [sys.executable, "-c", code, "--config", str(config), "--no-cache"],
        cwd=tree,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_every_mapped_package_is_listed_for_installation():
    setup = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["tool"]["setuptools"]
    listed = set(setup["packages"])
    on_disk, no_init = set(), set()
    for package, folder in setup["package-dir"].items():
        for module in (REPO / folder).rglob("*.py"):
            if "__pycache__" in module.parts:
                continue
            rel = module.parent.relative_to(REPO / folder)
            name = ".".join([package, *rel.parts])
            on_disk.add(name)
            if not (module.parent / "__init__.py").is_file():
                no_init.add(name)  # a namespace folder: `pip install .` would leave it out
    assert no_init == set(), "give these folders an __init__.py"
    # a sub-package mapped by a parent's folder (rti_rig/core under rti_rig) counts once
    assert on_disk - listed == set(), "add these to [tool.setuptools] packages"


@pytest.mark.slow
def test_the_layer_contract_holds(tmp_path):
    tree = installed_layout(tmp_path / "site")
    result = lint_imports(tree, PYPROJECT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "broken" not in result.stdout.lower() or "0 broken" in result.stdout.lower()


@pytest.mark.slow
def test_the_contract_fails_when_a_core_module_imports_a_driver(tmp_path):
    tree = installed_layout(tmp_path / "site")
    geometry = tree / "rti_rig" / "core" / "geometry.py"
    geometry.write_text(
        geometry.read_text(encoding="utf-8") + "\nimport rti_rig.drivers.led_dome.driver\n",
        encoding="utf-8",
    )
    result = lint_imports(tree, PYPROJECT)
    assert result.returncode != 0
    assert "rti_rig.core.geometry -> rti_rig.drivers.led_dome.driver" in result.stdout


#: The emulators' contracts, each with the import that breaks it: (module file under the
#: installed tree, the line appended, the contract's name, the edge import-linter reports).
EMULATOR_BREAKS = [
    (
        # the own dome protocols' emulator reads the spec, not the driver's codecs
        "rti_rig/simulator/own_protocols.py",
        "import rti_rig.drivers.led_dome.codec_default",
        "dome emulator reads docs/protocols/led-dome.md, not the driver's codecs",
        "rti_rig.simulator.own_protocols -> rti_rig.drivers.led_dome.codec_default",
    ),
    (
        # the emulated servos speak Protocol 2.0 from the e-manual (dynamixel_wire)
        "rti_rig/simulator/dynamixel_emulator.py",
        "from rti_rig.drivers.dynamixel import protocol2 as _p2  # noqa: F401",
        "Dynamixel emulator speaks Protocol 2.0 from the e-manual, not the driver's codec",
        "rti_rig.simulator.dynamixel_emulator -> rti_rig.drivers.dynamixel.protocol2",
    ),
    (
        # ... and name their registers from their own tables (dynamixel_table)
        "rti_rig/simulator/dynamixel_bus_time.py",
        "from rti_rig.drivers.dynamixel import control_table as _ct  # noqa: F401",
        "Dynamixel emulator reads its control tables from the e-manual, not the driver's",
        "rti_rig.simulator.dynamixel_bus_time -> rti_rig.drivers.dynamixel.control_table",
    ),
]


@pytest.mark.slow
def test_the_emulator_contracts_fail_when_an_emulator_imports_the_drivers_wire(tmp_path):
    """Each emulator is written from the device's published behaviour, not the driver's
    codec or register map: built on them again, a bug there would be on both sides of the
    wire and pass every driver test against the emulator. One tree, each contract broken by
    its own import, one run of the linter (each run takes seconds)."""
    tree = installed_layout(tmp_path / "site")
    for module, line, _, _ in EMULATOR_BREAKS:
        path = tree / module
        path.write_text(path.read_text(encoding="utf-8") + f"\n{line}\n", encoding="utf-8")
    result = lint_imports(tree, PYPROJECT)
    assert result.returncode != 0
    for _, _, contract, edge in EMULATOR_BREAKS:
        assert f"{contract} BROKEN" in result.stdout, (contract, result.stdout)
        assert edge in result.stdout, (edge, result.stdout)
