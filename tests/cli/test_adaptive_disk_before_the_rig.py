"""A new adaptive session the disk cannot hold is refused before the rig is built.

``rti-rig run RIG --adaptive --lights N`` (or ``--until-error``) with too little free disk
under ``--out`` had been refused only once the rig was built (the dome's port opened, the fit
warmed up: ~13 s on emulated_dome), when a planned run's refusal comes before it. The figure
asked for is what the session is sure to take, as the controller counts it once the rig is
built. Free space is faked with ``shutil.disk_usage``; building the rig is made to fail the
test.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

import rti_rig.app.compose
from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.parametrize(
    ("config", "extra", "count"),
    [
        ("simulated_dome.toml", ["--adaptive", "--lights", "20"], 20),
        ("emulated_dome.toml", ["--adaptive", "--lights", "20"], 20),
        ("simulated_dome.toml", ["--adaptive"], 48),  # every LED: no default_lights
        ("simulated_dome.toml", ["--until-error", "8"], 4),  # its starting lights
        ("simulated_dome.toml", ["--until-error", "8", "--min-lights", "6"], 6),
        ("simulated_dome.toml", ["--until-error", "8", "--lights", "10"], 10),
        ("simulated_arm.toml", ["--adaptive"], 24),  # the arm's default_lights
        ("simulated_arm.toml", ["--until-error", "8"], 4),
    ],
)
def test_an_adaptive_session_the_disk_cannot_hold_is_refused_before_the_rig_is_built(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, config: str, extra: list[str], count: int
) -> None:
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage._replace(free=1_000_000))

    def no_rig(*_a: object, **_k: object) -> None:
        raise AssertionError("the rig was built before the disk was checked")

    monkeypatch.setattr(rti_rig.app.compose, "build_rig", no_rig)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(CONFIGS / config), "--out", str(out), *extra])
    text = said(r)
    assert r.exit_code == 2, text
    assert f"not enough free disk space for {count} image(s)" in text, text
    assert "free space or choose another --out" in text, text
    assert "rig was built" not in text and "Traceback" not in text, text
    assert not out.exists()


@pytest.mark.parametrize(
    ("config", "lights", "until", "min_lights"),
    [
        ("simulated_dome.toml", 20, None, None),
        ("simulated_dome.toml", None, None, None),
        ("simulated_dome.toml", None, 8.0, None),
        ("simulated_dome.toml", None, 8.0, 6),
        ("simulated_dome.toml", 10, 8.0, None),
        ("simulated_arm.toml", None, None, None),
        ("simulated_arm.toml", None, 8.0, None),
        ("simulated_arm.toml", 30, None, None),
    ],
)
def test_the_figures_asked_before_the_rig_are_the_session_s_own(
    tmp_path: Path, config: str, lights: int | None, until: float | None, min_lights: int | None
) -> None:
    """What is asked of the disk before the rig is built is what the session, once planned on
    the built rig, is sure to take and may take at most: neither a session that fits refused
    nor one that does not let through."""
    from rti_rig.app.config import load_rig_config
    from rti_rig.app.usecases.adaptive import open_adaptive_session

    asked: list[tuple[int, int]] = []
    rig, _schedule, _folder, source = open_adaptive_session(
        load_rig_config(CONFIGS / config),
        tmp_path / "s",
        lights,
        until,
        min_lights=min_lights,
        check_room=lambda sure, most: asked.append((sure, most)),
    )
    rig.close()
    assert asked == [(source.sure_total, source.total)]
