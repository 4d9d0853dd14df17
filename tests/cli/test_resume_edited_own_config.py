"""A resume refused because the session's own config was edited says to set it back.

An arm session stopped part-way, its config's keep-out cone then widened in place: `rti-rig
run --resume DIR` loads that same edited file, so the refusal's advice "Resume with the
session's own config (rti-rig run --resume DIR)" sent the user round in a circle. Another
file given with --resume still gets that advice.
"""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, cut_new_session, write_config
from typer.testing import CliRunner

from rti_rig.app.usecases.session import NewSessionRequest
from rti_rig.cli import app
from rti_rig.runtime.controller import FinishReason

runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


def small_arm(tmp_path: Path, name: str, cone: str = "10.0") -> Path:
    text = (CONFIGS / "virtual_arm.toml").read_text()
    text = text.replace("width = 512", "width = 32").replace("height = 512", "height = 32")
    text = text.replace("keep_out_half_angle_deg = 10.0", f"keep_out_half_angle_deg = {cone}")
    text = text.replace("max_elevation_deg = 80.0", "max_elevation_deg = 55.0")
    return write_config(tmp_path, text, name)


def stopped_after(cfg: Path, out: Path, n: int) -> None:
    run = cut_new_session(NewSessionRequest(cfg, out, lights=8), after_step=n - 1)
    assert run.finish_reason is FinishReason.CANCELLED


def test_an_own_config_edited_in_place_is_to_be_set_back(tmp_path: Path) -> None:
    cfg = small_arm(tmp_path, "arm.toml")
    out = tmp_path / "s"
    stopped_after(cfg, out, 2)
    small_arm(tmp_path, "arm.toml", cone="30.0")  # the same file, edited
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "keep_out_half_angle_deg 10 → 30" in text
    assert "Resume with the session's own config" not in text  # that is what was just run
    assert "this session's own config, edited since the session began: set it back" in text
    assert str(out / "manifest.json") in text and "rig.config" in text

    other = small_arm(tmp_path, "other.toml", cone="20.0")
    r = runner.invoke(app, ["run", str(other), "--resume", str(out)])
    assert r.exit_code == 2, r.output
    assert f"Resume with the session's own config (rti-rig run --resume {out})" in said(r)
