"""A resume given another rig config file than the session's, describing the same rig.

`rti-rig run OTHER.toml --resume DIR` with a file that differs from the session's own only in
what the images do not depend on (its name, its description, a second dome of the same build)
is accepted. Its note had said that OTHER.toml "has been edited since the session began": a
claim about a file nobody had touched.
"""

from __future__ import annotations

from pathlib import Path

from conftest import SMALL_DOME, cut_new_session, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    """The command's output with rich's line wrapping undone."""
    return " ".join(result.output.split())


def _interrupted(tmp_path: Path) -> tuple[Path, Path]:
    """(config, session): a session of 6 lights on the small simulated dome, cancelled after
    its third image (as a Ctrl-C leaves it), to be resumed."""
    from rti_rig.app.usecases.session import NewSessionRequest
    from rti_rig.runtime.controller import FinishReason

    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    run = cut_new_session(NewSessionRequest(cfg, out, lights=6), after_step=2)
    assert run.finish_reason is FinishReason.CANCELLED
    return cfg, out


def test_another_config_file_is_not_said_to_have_been_edited(tmp_path: Path) -> None:
    cfg, out = _interrupted(tmp_path)
    other = write_config(
        tmp_path, SMALL_DOME.replace('name = "small"', 'name = "small-twin"'), "twin.toml"
    )
    r = runner.invoke(app, ["run", str(other), "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "edited" not in text, text
    assert f"{other} is not the rig config this session last ran with ({cfg})" in text, text
    assert "in nothing the images depend on" in text


def test_the_sessions_own_config_edited_is_still_said_to_be(tmp_path: Path) -> None:
    cfg, out = _interrupted(tmp_path)
    cfg.write_text(SMALL_DOME + "\n# a comment: nothing the images depend on\n")
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert f"{cfg} has been edited since the session began" in said(r), said(r)
