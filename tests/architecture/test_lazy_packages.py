"""The driver packages that load their names on first use (PEP 562) must show import-linter
every edge they hide: their ``TYPE_CHECKING`` block (which the contracts count, see
``exclude_type_checking_imports`` in pyproject.toml) imports exactly the names their lazy table
loads, from the same modules. Otherwise ``from rti_rig.drivers.led_dome import LedDomeDriver``
in the simulator would pass the contract that forbids the simulator a device driver."""

from __future__ import annotations

import ast
import importlib
import tomllib
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
LAZY = ["drivers/led_dome/__init__.py", "drivers/dynamixel/__init__.py"]


def _tables(path: Path) -> tuple[dict[str, str], dict[str, str]]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    lazy: dict[str, str] = {}
    typed: dict[str, str] = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "_WHERE" for t in node.targets
        ):
            lazy = ast.literal_eval(node.value)
        if (
            isinstance(node, ast.If)
            and isinstance(node.test, ast.Name)
            and node.test.id == "TYPE_CHECKING"
        ):
            for imp in node.body:
                assert isinstance(imp, ast.ImportFrom) and imp.module is not None
                typed.update({a.name: imp.module for a in imp.names})
    return lazy, typed


@pytest.mark.parametrize("rel", LAZY)
def test_the_type_checking_block_mirrors_the_lazy_table(rel: str) -> None:
    lazy, typed = _tables(REPO / rel)
    assert lazy, f"{rel}: no _WHERE table"
    assert lazy == typed


@pytest.mark.parametrize("rel", LAZY)
def test_every_lazy_name_loads(rel: str) -> None:
    lazy, _ = _tables(REPO / rel)
    package = "rti_rig." + rel.removesuffix("/__init__.py").replace("/", ".")
    mod = importlib.import_module(package)
    for name, where in lazy.items():
        assert getattr(mod, name) is getattr(importlib.import_module(where), name)
    assert sorted(mod.__all__) == sorted(lazy)


def test_the_contracts_count_type_checking_imports() -> None:
    config = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))
    assert config["tool"]["importlinter"].get("exclude_type_checking_imports") is False


@pytest.mark.parametrize("rel", LAZY)
def test_an_unknown_name_is_an_attribute_error(rel: str) -> None:
    package = "rti_rig." + rel.removesuffix("/__init__.py").replace("/", ".")
    mod = importlib.import_module(package)
    with pytest.raises(AttributeError, match="no attribute 'NoSuchDriver'"):
        mod.NoSuchDriver  # noqa: B018
    with pytest.raises(ImportError):
        exec(f"from {package} import NoSuchDriver", {})
