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


@pytest.mark.slow
def test_the_contract_fails_when_the_own_protocols_emulator_imports_a_driver_codec(tmp_path):
    """The emulator of rti-rig's own dome protocols reads the spec, not the driver's codecs:
    built on them, a codec bug would be on both sides of the wire and pass every test."""
    tree = installed_layout(tmp_path / "site")
    own = tree / "rti_rig" / "simulator" / "own_protocols.py"
    own.write_text(
        own.read_text(encoding="utf-8") + "\nimport rti_rig.drivers.led_dome.codec_default\n",
        encoding="utf-8",
    )
    result = lint_imports(tree, PYPROJECT)
    assert result.returncode != 0
    assert "dome emulator reads docs/protocols/led-dome.md, not the driver's codecs" in (
        result.stdout
    )
    assert "BROKEN" in result.stdout
    assert "rti_rig.simulator.own_protocols -> rti_rig.drivers.led_dome.codec_default" in (
        result.stdout
    )


@pytest.mark.slow
def test_the_contract_fails_when_the_dynamixel_emulator_imports_the_driver_codec(tmp_path):
    """The emulated servos speak Protocol 2.0 from the e-manual (dynamixel_wire), not through
    the driver's codec: built on it again, a codec bug would be on both sides of the wire."""
    tree = installed_layout(tmp_path / "site")
    emulator = tree / "rti_rig" / "simulator" / "dynamixel_emulator.py"
    emulator.write_text(
        emulator.read_text(encoding="utf-8")
        + "\nfrom rti_rig.drivers.dynamixel import protocol2 as _p2  # noqa: F401\n",
        encoding="utf-8",
    )
    result = lint_imports(tree, PYPROJECT)
    assert result.returncode != 0
    assert "Dynamixel emulator speaks Protocol 2.0 from the e-manual, not the driver's codec" in (
        result.stdout
    )
    assert "BROKEN" in result.stdout
    assert "rti_rig.simulator.dynamixel_emulator -> rti_rig.drivers.dynamixel.protocol2" in (
        result.stdout
    )


@pytest.mark.slow
def test_the_contract_fails_when_the_dynamixel_emulator_imports_the_driver_table(tmp_path):
    """The emulated servos name their registers from their own e-manual tables
    (simulator/dynamixel_table.py), not the driver's control_table: built on it again, a
    register-map bug would be on both sides of the wire."""
    tree = installed_layout(tmp_path / "site")
    emulator = tree / "rti_rig" / "simulator" / "dynamixel_emulator.py"
    emulator.write_text(
        emulator.read_text(encoding="utf-8")
        + "\nfrom rti_rig.drivers.dynamixel import control_table as _ct  # noqa: F401\n",
        encoding="utf-8",
    )
    result = lint_imports(tree, PYPROJECT)
    assert result.returncode != 0
    assert "Dynamixel emulator reads its control tables from the e-manual, not the driver's" in (
        result.stdout
    )
    assert "BROKEN" in result.stdout
    assert "rti_rig.simulator.dynamixel_emulator -> rti_rig.drivers.dynamixel.control_table" in (
        result.stdout
    )
