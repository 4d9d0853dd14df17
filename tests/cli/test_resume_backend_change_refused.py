"""``run --resume S --accept-rig-change`` on a config of another backend is refused.

Before: a session shot on emulated_dome.toml, resumed with the same config but ``backend =
"simulated"`` and ``--accept-rig-change``, went on ("rig change accepted: backend: emulated →
simulated"), and one session held images from two backends. The backend is what the images
come from (a dry run's renders, a real camera's photographs, a replayed acquisition's files),
so like the kind of rig it is never accepted; the refusal says so, changes nothing, and names
the session's own config and a new session's command.
"""

from __future__ import annotations

import signal
from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.testing.kill_hooks import popen_session


def _files(out: Path) -> dict[str, bytes]:
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in out.rglob("*") if p.is_file()}


def test_a_backend_change_is_not_accepted(tmp_path: Path) -> None:
    text = (CONFIGS / "emulated_dome.toml").read_text()
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    assert text.count('backend = "emulated"') == 1
    emulated = tmp_path / "em.toml"
    emulated.write_text(text)
    simulated = tmp_path / "sim.toml"
    simulated.write_text(text.replace('backend = "emulated"', 'backend = "simulated"'))
    out = tmp_path / "s"
    proc = popen_session("after_journal", 2, emulated, out, 6)
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    before = _files(out)

    r = CliRunner().invoke(
        app, ["run", str(simulated), "--resume", str(out), "--accept-rig-change", "--no-verdict"]
    )

    message = said(r)
    assert r.exit_code == 2, message
    assert "(1 difference: backend: emulated → simulated)" in message, message
    assert "Its backend is 'simulated', and this session was begun on 'emulated'" in message
    assert "cannot be accepted into this session, even with --accept-rig-change" in message
    assert f"Resume with the session's own config, {emulated}" in message, message
    assert "rig change accepted" not in message
    assert _files(out) == before
