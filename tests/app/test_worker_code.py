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
from typing import Any

import pytest

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
    mine = local_identity()
    assert mine == WorkerCode(rti_rig.__version__, first["fingerprint"], None, mine.stack)
    # the libraries a worker must agree on, as this process imports them (numpy by its major)
    import cloudpickle
    import dask
    import distributed
    import numpy

    assert dict(mine.stack) == {
        "python": f"{sys.version_info[0]}.{sys.version_info[1]}",  # to its minor
        "distributed": distributed.__version__,
        "dask": dask.__version__,
        "cloudpickle": cloudpickle.__version__,
        "numpy": numpy.__version__.split(".")[0] + ".x",
    }


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


#: Deletes one file of the rti-rig it imports while the check reads it, as a `git checkout` or
#: a reinstall on a worker does, then prints the check's answer. argv: the file, and whether
#: it goes before it is read (listed, then gone) or just after (read, then gone before the
#: dates of a process that imported rti-rig first are asked).
_VANISHING = """
import pathlib, sys
from rti_rig.app.usecases.worker_code import _identity_function
target, when = pathlib.Path(sys.argv[1]).resolve(), sys.argv[2]
read_bytes = pathlib.Path.read_bytes
def deleting(self):
    if self.resolve() == target and when == "before":
        self.unlink()
    data = read_bytes(self)
    if self.resolve() == target and when == "after":
        self.unlink()
    return data
pathlib.Path.read_bytes = deleting
print(repr(_identity_function()()))
"""


def _checked_as_it_vanishes(script: str, tree: Path, target: Path, *args: str) -> Any:
    """The worker check's answer from ``script`` run on the rti-rig at ``tree`` (a fresh
    interpreter, nothing else on its path), which removes ``target`` during the check; the
    script must end without an exception and ``target`` be gone."""
    done = subprocess.run(
        [sys.executable, "-c", script, str(target), *args], capture_output=True, text=True,
        env={"PYTHONPATH": str(tree), "PATH": ""}, cwd=tree.parent, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr  # no FileNotFoundError out of the check
    assert not target.exists()
    return ast.literal_eval(done.stdout.strip())


@pytest.mark.parametrize("when", ["before", "after"])
def test_a_source_file_that_vanishes_while_it_is_checked_is_named_with_restart(
    tmp_path: Path, when: str
) -> None:
    """A ``.py`` of a worker's rti-rig deleted between the listing of its folder and the read
    of that file (or the read of its date) had failed the check there with a bare
    ``FileNotFoundError``, which the fit said as a worker it "could not ask" (check that it
    is running and reachable). The check says that file vanished and the worker must be
    restarted; the fit names the worker with it."""
    tree = _wheel_layout(tmp_path / "tree")
    target = (
        tree
        / "rti_rig"
        / "planner"
        / sorted(p.name for p in (tree / "rti_rig" / "planner").glob("*.py"))[-1]
    )
    answer = _checked_as_it_vanishes(_VANISHING, tree, target, when)
    problem = answer["problem"]
    assert problem and f"rti_rig/planner/{target.name} vanished while it was being checked" in (
        problem
    ), answer
    assert "restart it" in problem, answer

    class _Client:
        def run(self, function, on_error):  # type: ignore[no-untyped-def]
            return {"tcp://w:1": answer}

    worker = worker_identities(_Client())["tcp://w:1"]
    assert isinstance(worker, WorkerCode) and worker != local_identity()  # not this code
    said = describe(worker)  # with its code when every file was read before one went
    assert said.startswith(f"rti-rig {rti_rig.__version__}") and said.endswith(f", but {problem}")
    assert "code None" not in said, said


#: Removes one folder of the rti-rig it imports just as the check is about to list it (listed
#: in its parent, then gone: a checkout that drops a subpackage), then prints the answer.
_FOLDER_VANISHING = """
import os, pathlib, shutil, sys
from rti_rig.app.usecases.worker_code import _identity_function
target = pathlib.Path(sys.argv[1]).resolve()
scandir = os.scandir
def vanishing(path="."):
    if not isinstance(path, int) and pathlib.Path(path).resolve() == target and target.exists():
        shutil.rmtree(target)
    return scandir(path)
os.scandir = vanishing
print(repr(_identity_function()()))
"""


def test_a_source_folder_that_vanishes_while_it_is_listed_is_named_with_restart(
    tmp_path: Path,
) -> None:
    """A subfolder of a worker's rti-rig removed between the listing of its parent and its own
    listing (a ``git checkout`` of a branch without that subpackage) failed the check with a
    bare ``FileNotFoundError`` from the folder walk, said as a worker that could not be asked,
    though a vanished file was named. The folder is named, with the restart."""
    tree = _wheel_layout(tmp_path / "tree")
    target = tree / "rti_rig" / "extra_subpackage"
    target.mkdir()
    (target / "__init__.py").write_text('"""A subpackage a checkout drops."""\n')
    answer = _checked_as_it_vanishes(_FOLDER_VANISHING, tree, target)
    problem = answer["problem"]
    assert answer["fingerprint"] is None, answer
    assert problem and "rti_rig/extra_subpackage/ vanished while it was being checked" in (
        problem
    ), answer
    assert "restart it" in problem, answer
