"""A tethered DSLR unplugged at a shot's download in ``rti-rig preview`` and at a metering
shot of ``run --auto-exposure``, on the shipped DSLR example (its dome firmware emulated on
a pty, python-gphoto2 replaced by tests/fake_gphoto2.py).

Why: a gone camera was told "continue with 'rti-rig run --resume SESSION'" and, at a
download, "its step is not recorded, so the resume shoots it again" whatever the command: a
preview (run again, never resumed) and a metering shot (no session: the run said "nothing
was captured or written") were sent to a resume of nothing.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import shipped_dome_on_pty
from fake_gphoto2 import Body, make_module
from test_dslr_download_disk_full import _config, _raw
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


@pytest.mark.parametrize(
    ("command", "again"),
    [
        (["preview"], "Reconnect it, then run the same 'rti-rig preview' again"),
        (
            ["run", "--auto-exposure", "--lights", "4"],
            "Reconnect it, then run the command again",
        ),
    ],
)
def test_a_camera_unplugged_at_a_download_outside_a_session_s_step_names_no_resume(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, command: list[str], again: str
) -> None:
    cfg = _config(tmp_path, "Internal RAM")
    body = Body(render=_raw, off_at_call=("file_get", 1))
    monkeypatch.setitem(sys.modules, "gphoto2", make_module(body))
    out = tmp_path / "s"
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, [command[0], str(cfg), "--out", str(out), *command[1:]])
        lit_at_end = firmware.lit
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert "This shot was taken but its file /IMG_0001.CR2" in said, said
    assert "so it is lost: /IMG_0001.CR2 existed only there" in said, said
    assert again in said, said
    assert "--resume" not in said and "the resume shoots it again" not in said, said
