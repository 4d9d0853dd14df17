"""``rti-rig --version`` names the code that runs, as a session's manifest records it."""

from __future__ import annotations

from typer.testing import CliRunner

import rti_rig
from rti_rig.cli import app
from rti_rig.runtime.session import software_versions


def test_version_prints_what_a_manifest_records_and_exits() -> None:
    result = CliRunner().invoke(app, ["--version"])
    assert result.exit_code == 0, result.output
    versions = software_versions()
    line = result.output.strip()
    assert line.startswith(f"rti-rig {rti_rig.__version__} (Python {versions['python']}"), line
    assert f"numpy {versions['numpy']}" in line and f"OpenCV {versions['opencv']}" in line


def test_version_before_a_command_runs_no_command() -> None:
    result = CliRunner().invoke(app, ["--version", "run", "no-such.toml"])
    assert result.exit_code == 0, result.output
    assert "no-such.toml" not in result.output
