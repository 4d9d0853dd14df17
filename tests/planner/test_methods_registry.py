"""Planning methods are a registry: the worked example of docs/extending.md plugs in as written."""

from __future__ import annotations

import importlib
import re
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import angle_between_deg
from rti_rig.core.lp_format import read_lp
from rti_rig.planner import methods
from rti_rig.planner.make_plan import plan_with_report

REPO = Path(__file__).resolve().parents[2]
DOC = REPO / "docs" / "extending.md"
DOME = REPO / "rig_configs" / "simulated_dome.toml"


def doc_example() -> str:
    text = DOC.read_text(encoding="utf-8")
    block = re.search(r"```python\n(# my_methods/farthest.py\n.*?)```", text, re.S)
    assert block, "docs/extending.md lost its worked example"
    return block.group(1)


@pytest.fixture
def farthest(tmp_path, monkeypatch):
    """The documented module, written where it says and imported as a user would; unregistered
    afterwards."""
    package = tmp_path / "my_methods"
    package.mkdir()
    (package / "__init__.py").write_text("", encoding="utf-8")
    (package / "farthest.py").write_text(doc_example(), encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    importlib.import_module("my_methods.farthest")
    yield methods.get_method("farthest")
    methods._METHODS.pop("farthest", None)
    for name in ("my_methods.farthest", "my_methods"):
        sys.modules.pop(name, None)


def test_the_built_ins_are_registered_in_help_order():
    assert methods.method_names()[:3] == ("uniform", "kmeans", "optimal")


def test_an_unknown_method_is_refused_with_the_registered_names():
    with pytest.raises(ScheduleError, match="choose uniform, kmeans, optimal"):
        methods.get_method("nearest")


def test_a_name_is_registered_once(farthest):
    with pytest.raises(ValueError, match="already registered"):
        methods.register_method(type(farthest)())


def test_the_documented_method_plans_through_the_cli(farthest, tmp_path):
    out = tmp_path / "plan.lp"
    args = ["plan", "--rig", str(DOME), "--lights", "8", "--method", "farthest"]
    r = CliRunner().invoke(app, [*args, "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert "Planned 8 lights (farthest, normals)" in said(r)
    dirs = np.array([e.direction for e in read_lp(out)])
    assert len(dirs) == 8
    # farthest-point sampling spreads the lights: no two closer than the dome's ring spacing
    gaps = [angle_between_deg(a, b) for i, a in enumerate(dirs) for b in dirs[i + 1 :]]
    assert min(gaps) > 20.0


def test_the_documented_method_is_scored_when_a_preview_gives_a_surface(farthest):
    from rti_rig.app.config import load_rig_config, rig_geometry

    geometry = rig_geometry(load_rig_config(DOME))
    rng = np.random.default_rng(1)
    preview = (0.3 + 0.4 * rng.random((64, 64))).astype(np.float32)
    schedule, report = plan_with_report(preview, geometry, 8, "farthest")
    assert len(schedule) == 8 and "farthest" in report.expected
    assert report.method == "farthest"
