"""The code fingerprint compared between this machine and a Dask cluster's workers covers every
package rti-rig installs (it had hashed the ``rti_rig/`` folder alone: in an editable install
two workers with different planner, driver or simulator code passed), and it depends on the
files' content only, not on where or how they are laid out."""

from __future__ import annotations

import ast
import importlib
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import rti_rig
from rti_rig.app.usecases.worker_code import (
    MAPPED_PACKAGES,
    Unasked,
    WorkerCode,
    describe,
    local_identity,
    worker_identities,
)

REPO = Path(__file__).resolve().parents[2]
_COPY_IGNORE = shutil.ignore_patterns("__pycache__")


def _wheel_layout(where: Path) -> Path:
    """This rti-rig laid out as ``pip install .`` lays it out: the mapped packages inside
    ``rti_rig/`` (the test's own install may be editable, with them in top-level folders)."""
    package = where / "rti_rig"
    shutil.copytree(Path(rti_rig.__file__).parent, package, ignore=_COPY_IGNORE)
    for name in MAPPED_PACKAGES:
        source = Path(importlib.import_module(name).__path__[0])
        shutil.copytree(source, package / name.rpartition(".")[2], ignore=_COPY_IGNORE)
    return where


def _fingerprint_in(tree: Path | None, cwd: Path) -> dict[str, str | None]:
    """The identity function's answer in a fresh interpreter importing rti_rig from ``tree``
    (or from this environment's install when ``None``), run in ``cwd`` (not the checkout)."""
    script = (
        "from rti_rig.app.usecases.worker_code import _identity_function\n"
        "print(repr(_identity_function()()))\n"
    )
    env = None if tree is None else {"PYTHONPATH": str(tree), "PATH": ""}
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, env=env, cwd=cwd,
        timeout=300, check=True,
    )  # fmt: skip
    return ast.literal_eval(done.stdout.strip())


def test_mapped_packages_are_pyproject_s_package_dir_mapping() -> None:
    config = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))
    mapped = set(config["tool"]["setuptools"]["package-dir"]) - {"rti_rig"}
    assert set(MAPPED_PACKAGES) == mapped


def test_a_planner_file_changes_the_fingerprint_and_the_layout_does_not(tmp_path: Path) -> None:
    one = _wheel_layout(tmp_path / "one")
    two = _wheel_layout(tmp_path / "elsewhere" / "two")
    changed = _wheel_layout(tmp_path / "changed")
    planner = sorted((changed / "rti_rig" / "planner").glob("*.py"))[-1]
    planner.write_text(planner.read_text(encoding="utf-8") + "\n# changed\n", encoding="utf-8")

    first, second, third = (_fingerprint_in(t, tmp_path) for t in (one, two, changed))
    assert first["problem"] is None and first["fingerprint"]
    assert first == second  # the same content in another folder
    assert third["fingerprint"] != first["fingerprint"]
    # the same content, mapped from top-level folders by this environment's install
    assert _fingerprint_in(None, tmp_path) == first
    assert local_identity() == WorkerCode(rti_rig.__version__, first["fingerprint"], None)


def test_a_missing_version_is_none_not_a_sentinel_that_reads_as_unknown() -> None:
    class _Client:
        def run(self, function, on_error):  # type: ignore[no-untyped-def]
            return {
                "a": {"version": None, "fingerprint": "abc", "problem": None},
                "b": OSError("reset"),
                "c": {"version": None, "fingerprint": None, "problem": "ModuleNotFoundError: x"},
            }

    found = worker_identities(_Client())
    assert found["a"] == WorkerCode(None, "abc", None)
    assert found["b"] == Unasked("OSError: reset")
    assert describe(found["a"]) == "rti-rig (no version), code abc"
    assert describe(found["c"]) == "no rti-rig (ModuleNotFoundError: x)"  # type: ignore[arg-type]
