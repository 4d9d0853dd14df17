"""A tethered DSLR unplugged while a shot's RAW is downloaded, through `rti-rig run` on the
shipped DSLR example (its dome firmware emulated on a pty, python-gphoto2 replaced at its
API boundary by tests/fake_gphoto2.py), then `--resume` once it is plugged back in.

The shot is taken; its download, or the wait for the body's announcement of its files, fails
with libgphoto2's -7 (I/O error), and every call after it too. The stop said only "the camera
stopped answering during 'download' … Images already taken are kept": nothing of the shot
just taken, lost with the camera's RAM or left on its card (never deleted before it is
downloaded).
"""

from __future__ import annotations

import sys

import pytest
from conftest import shipped_dome_on_pty
from fake_gphoto2 import Body, make_module
from test_dslr_download_disk_full import _config, _raw  # the same shipped DSLR, small
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


@pytest.mark.parametrize("target", ["Internal RAM", "Memory card"])
@pytest.mark.parametrize("op", ["file_get", "wait_for_event"])
def test_a_camera_unplugged_at_a_download_says_where_the_shot_is_and_the_resume_shoots_it(
    tmp_path, monkeypatch, target, op
):
    """Unplugged at the third shot's download, or as the body announces its files (the
    event wait after the capture returned): the third shot is taken, never downloaded."""
    cfg = _config(tmp_path, target)
    body = Body(render=_raw, off_at_call=(op, 3))
    monkeypatch.setitem(sys.modules, "gphoto2", make_module(body))
    out = tmp_path / "s"
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
        lit_at_end = firmware.lit
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert body.shots == 3, body.shots
    assert f"stopped answering during '{'download' if op == 'file_get' else op}'" in said, said
    assert "This shot was taken but its file" in said and "IMG_0003.CR2" in said, said
    assert "it is shot again when the session goes on" in said, said
    assert f"Continue with: rti-rig run --resume {out}" in said, said
    if target == "Internal RAM":
        assert "so it is lost: /IMG_0003.CR2 existed only there" in said, said
    else:
        assert "stays on the camera's card at /store_00020001/DCIM/100CANON/IMG_0003.CR2" in said
        assert "IMG_0003.CR2" in body.card and "IMG_0003.CR2" not in body.deleted
    assert (out / "lights.lp").read_text().split()[0] == "2"
    assert sorted(p.name for p in (out / "raw").glob("*.cr2")) == [
        "image_001.cr2",
        "image_002.cr2",
    ]

    body.switch_on()  # plugged back in
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, " ".join(r.output.split())
    assert (out / "lights.lp").read_text().split()[0] == "4"
    for k in range(1, 5):
        assert (out / f"raw/image_{k:03d}.cr2").read_bytes() == _raw(body)


@pytest.mark.parametrize(
    "gone",
    [{"failures": {"get_config": [-7]}}, {"off_at_shot": 1}],
    ids=["as it is opened", "at the first shot"],
)
def test_a_camera_gone_before_any_image_is_kept_claims_no_image_kept(tmp_path, monkeypatch, gone):
    """Gone as it is opened (its settings read after init), or at the first shot: the run
    keeps nothing and says so. The camera's error had gone on "Images already taken are kept:
    reconnect it, then continue with 'rti-rig run --resume SESSION'" (a template, and a
    resume of a session that holds no image)."""
    cfg = _config(tmp_path, "Memory card")
    body = Body(render=_raw, **gone)
    monkeypatch.setitem(sys.modules, "gphoto2", make_module(body))
    out = tmp_path / "s"
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "2"])
        lit_at_end = firmware.lit
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert body.shots == 0 and "Nothing was captured" in said, said
    assert "the camera stopped answering" in said, said
    assert "Images already taken are kept" not in said, said
    assert "SESSION" not in said and "--resume" not in said, said
    assert "Reconnect it, then go on as said above" in said, said
