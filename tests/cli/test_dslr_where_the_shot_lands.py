"""Where a tethered DSLR puts its shots, and a card copy whose delete fails, through `rti-rig
check` and `rti-rig run` on the shipped DSLR example (its dome firmware emulated on a pty,
python-gphoto2 replaced at its API boundary by tests/fake_gphoto2.py).

Why: a failed delete of a downloaded shot's card copy was suppressed without a word (the card
filling as the session went on), and the camera's folder was never compared with the
``capture_target`` asked: a body writing to its card when its RAM was asked, or keeping the
shot in RAM when the card was asked (no backup copy where the user counted on one), was unsaid.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import journal, manifest
from fake_gphoto2 import Body
from test_dslr_download_disk_full import _config, _raw, _shot_with

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

UNDELETED = "the camera's card copy of a shot could not be deleted there after its download"


def test_a_card_copy_whose_delete_fails_is_said_once_and_the_download_kept(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = _config(tmp_path, "Memory card")
    body = Body(render=_raw, failures={"file_delete": [-1] * 10})
    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "3"]
    )
    assert r.exit_code == 0 and lit_at_end is None, said
    assert said.count(UNDELETED) == 1, said
    assert "(gphoto2 error -1: a locked or write-protected card" in said, said
    assert "[3 of 3 images]" in said.split(UNDELETED)[1], said
    assert sorted(body.card) == ["IMG_0001.CR2", "IMG_0002.CR2", "IMG_0003.CR2"], body.card
    assert len(list((out / "raw").glob("image_*.cr2"))) == 3
    assert all(UNDELETED in " ".join(step["notices"]) for step in journal(out))
    assert any(UNDELETED in n for n in manifest(out)["notices"])


def test_a_card_copy_whose_delete_fails_is_said_by_the_check(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = _config(tmp_path, "Memory card")
    body = Body(render=_raw, failures={"file_delete": [-1]})
    r, said, _ = _shot_with(monkeypatch, cfg, body, ["check", str(cfg)])
    assert r.exit_code == 0 and "RESULT: PASS" in said, said
    assert f"note: {UNDELETED}" in said and list(body.card) == ["IMG_0001.CR2"], said


@pytest.mark.parametrize("command", ["check", "run"])
def test_a_body_writing_to_its_card_when_its_ram_was_asked_is_said(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, command: str
) -> None:
    cfg = _config(tmp_path, "Internal RAM")
    body = Body(render=_raw, stores_in="card")
    argv = [command, str(cfg)] + (
        ["--out", str(tmp_path / "s"), "--lights", "2"] * (command == "run")
    )
    r, said, _ = _shot_with(monkeypatch, cfg, body, argv)
    assert r.exit_code == 0, said
    assert (
        "the camera dslr (Canon EOS 600D on usb:001,005) wrote its shots to its card "
        f"({body.card_dir()}/), not to its RAM as capture_target = 'Internal RAM' asks: each is "
        "deleted there once downloaded"
    ) in said, said
    assert said.count("wrote its shots to its card") == 1, said
    assert body.card == {}, body.card


def test_a_body_keeping_its_shots_in_ram_when_its_card_was_asked_is_said(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = _config(tmp_path, "Memory card")
    cfg.write_text(
        cfg.read_text().replace("busy_retries = 6", "busy_retries = 6\ndelete_from_camera = false")
    )
    body = Body(render=_raw, stores_in="ram")
    out = tmp_path / "s"
    r, said, _ = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "2"]
    )
    assert r.exit_code == 0, said
    assert "kept its shots in its RAM, not on its card as capture_target = 'Memory card'" in said
    assert "no copy of them stays on the card; the session's raw/ holds the only one" in said
    assert said.count("kept its shots in its RAM") == 1 and body.card == {}, said
