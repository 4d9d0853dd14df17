"""An install hint names the pip of the environment running rti-rig.

The README installs rti-rig into ``.venv`` and runs ``.venv/bin/rti-rig`` without activating
it: a bare ``pip install gphoto2`` pasted into that shell installs into another environment (or
is refused by the system's, "externally managed"), and rti-rig goes on saying it is missing.
"""

from __future__ import annotations

import shlex
import sys

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app


def test_check_without_python_gphoto2_says_this_environments_pip(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setitem(sys.modules, "gphoto2", None)  # `import gphoto2` raises ImportError
    r = CliRunner().invoke(app, ["check", str(CONFIGS / "example_dome_48.toml")])
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "Traceback" not in said, said
    command = f"{shlex.quote(sys.executable)} -m pip install gphoto2"
    assert f"python-gphoto2 is not installed: {command} (" in said, said
