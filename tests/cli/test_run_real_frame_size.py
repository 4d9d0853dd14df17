"""A camera whose frames are not the ``[camera]`` width x height: the run says so once, naming
the keys, and checks the disk again for the images left at the real size.

Found by a review: ``[camera] width``/``height`` default to 512 x 512 and were never compared
with a real camera's frames, so the disk check before a session counted a 24 MP camera's
images as 0.26 MP and let a session start that the disk could not hold.

The simulated camera renders the config's size, so the camera's real size is faked here at its
capture (each frame upscaled 4 x 4, as a camera larger than its config delivers), and the disk's
free space at ``shutil.disk_usage`` (room for the config's size, not the real one).
"""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import CONFIGS, write_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp
from rti_rig.simulator.sim_camera import SimulatedCamera

runner = CliRunner()
LIGHTS = 8


def _said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


@pytest.fixture
def bigger_camera(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The shipped simulated dome at 64 x 64 px, its camera delivering 256 x 256 px frames."""
    text = (CONFIGS / "simulated_dome.toml").read_text(encoding="utf-8")
    assert "width = 512\nheight = 512" in text
    cfg = write_config(
        tmp_path, text.replace("width = 512\nheight = 512", "width = 64\nheight = 64")
    )
    capture = SimulatedCamera.capture

    def larger(self: SimulatedCamera, exposure_s: float):  # type: ignore[no-untyped-def]
        frame = capture(self, exposure_s)
        pixels = np.repeat(np.repeat(frame.pixels, 4, axis=0), 4, axis=1)
        return dataclasses.replace(frame, pixels=pixels)

    monkeypatch.setattr(SimulatedCamera, "capture", larger)
    return cfg


def test_a_disk_too_small_for_the_real_size_is_refused_after_the_first_image(
    tmp_path: Path, bigger_camera: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    usage = shutil.disk_usage(tmp_path)
    # 10 MB: room for 8 images of 64 x 64 px (and the 8 MB margin), not for 7 of 256 x 256
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage._replace(free=10_000_000))
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(bigger_camera), "--out", str(out), "--lights", str(LIGHTS)])
    said = _said(r)
    assert r.exit_code == 2, r.output
    assert "The camera delivers 256 x 256 px images" in said, said
    assert "camera.width = 256 and camera.height = 256" in said and "64 x 64 px" in said
    assert "not enough free disk space for 7 image(s)" in said, said
    assert "free at least" in said and f"--resume {out}" in said, said
    assert "1 image(s) kept" in said, said
    assert len(read_lp(out / "lights.lp")) == 1


def test_the_wrong_size_is_said_once_and_a_disk_with_room_goes_on(
    tmp_path: Path, bigger_camera: Path
) -> None:
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(bigger_camera), "--out", str(out), "--lights", str(LIGHTS)])
    said = _said(r)
    assert r.exit_code == 0, r.output
    assert said.count("The camera delivers 256 x 256 px images") == 1, said
    assert len(read_lp(out / "lights.lp")) == LIGHTS


def test_a_resume_counts_the_disk_at_the_real_size_and_does_not_say_it_again(
    tmp_path: Path, bigger_camera: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The session stopped by the disk after its first image is resumed: the resume had
    counted the disk at the config's 64 x 64 again (let through, it took one more image before
    the same refusal) and, once room was made, said the config's size was wrong again as if
    newly found, telling the user to set the keys, which the resume then refuses."""
    import json

    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage._replace(free=10_000_000))
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(bigger_camera), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 2 and len(read_lp(out / "lights.lp")) == 1, r.output
    seen = json.loads((out / "manifest.json").read_text())["rig"]["frame_size"]
    assert seen == {"frames": [256, 256], "config": [64, 64]}
    # 10 MB hold the 7 left at 64 x 64, not at the 256 x 256 the camera delivers
    r = runner.invoke(app, ["run", "--resume", str(out)])
    said = _said(r)
    assert r.exit_code == 2, said
    assert "not enough free disk space to go on with" in said, said
    assert "the 7 image(s) still to shoot" in said and "capturing" not in said, said
    assert len(read_lp(out / "lights.lp")) == 1
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage)
    r = runner.invoke(app, ["run", "--resume", str(out)])
    said = _said(r)
    assert r.exit_code == 0, said
    assert "The camera delivers" not in said, said
    assert len(read_lp(out / "lights.lp")) == LIGHTS
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["rig"]["frame_size"] == seen


def _stopped_by_the_disk_at_its_own_size(
    tmp_path: Path, bigger_camera: Path, monkeypatch: pytest.MonkeyPatch
) -> tuple[Path, Any]:
    """A session of ``bigger_camera`` stopped by a 10 MB disk after its first image, its
    camera delivering 256 x 256 px frames whatever the config's keys say (a camera's size is
    its own); returns its folder and the disk's real usage (to make room with). The run told
    the user to set the keys: what the resume tests then do."""
    capture = SimulatedCamera.capture

    def its_own_size(self: SimulatedCamera, exposure_s: float):  # type: ignore[no-untyped-def]
        frame = capture(self, exposure_s)  # the fixture's: 4 x the config's size
        step = frame.pixels.shape[0] // 256
        return dataclasses.replace(frame, pixels=frame.pixels[::step, ::step])

    monkeypatch.setattr(SimulatedCamera, "capture", its_own_size)
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage._replace(free=10_000_000))
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(bigger_camera), "--out", str(out), "--lights", str(LIGHTS)])
    said = _said(r)
    assert r.exit_code == 2 and "set camera.width = 256 and camera.height = 256 there" in said
    return out, usage


def test_a_session_resumed_with_the_keys_set_as_told_goes_on(
    tmp_path: Path, bigger_camera: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Stopped by the disk after the note, the keys set as it says, then resumed: the resume
    had been refused as another picture ("camera size: 64×64 → 256×256"), though the camera's
    images were 256 x 256 all along. A camera's size is its own, whatever the config says: the
    fake camera here delivers 256 x 256 px frames at either setting."""
    import json

    out, usage = _stopped_by_the_disk_at_its_own_size(tmp_path, bigger_camera, monkeypatch)
    text = bigger_camera.read_text(encoding="utf-8")
    bigger_camera.write_text(text.replace("width = 64\nheight = 64", "width = 256\nheight = 256"))
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage)
    r = runner.invoke(app, ["run", "--resume", str(out)])
    said = _said(r)
    assert r.exit_code == 0, said
    assert "The camera delivers" not in said, said
    assert len(read_lp(out / "lights.lp")) == LIGHTS
    rig = json.loads((out / "manifest.json").read_text())["rig"]
    assert rig["identity"]["camera_size"] == "64×64"  # as the session began, beside the real
    assert rig["frame_size"] == {"frames": [256, 256], "config": [64, 64]}


@pytest.mark.parametrize(("keys", "goes_on"), [(256, True), (128, False)])
def test_a_session_from_before_the_record_resumed_with_the_keys_set_as_told_goes_on(
    tmp_path: Path,
    bigger_camera: Path,
    monkeypatch: pytest.MonkeyPatch,
    keys: int,
    goes_on: bool,
) -> None:
    """A session begun before the manifest recorded ``rig.frame_size`` (its run said the same
    "set camera.width = 256 and camera.height = 256 there"), resumed with the keys set as
    told: it had been refused as another picture ("camera size: 64×64 → 256×256"; "images
    shot now would not match the ones already taken"), its images 256 x 256 all along. Its
    first image's size stands for the record; keys set to another size are still refused."""
    import json

    out, usage = _stopped_by_the_disk_at_its_own_size(tmp_path, bigger_camera, monkeypatch)
    manifest = json.loads((out / "manifest.json").read_text())
    del manifest["rig"]["frame_size"]  # as a manifest written before the record
    (out / "manifest.json").write_text(json.dumps(manifest, indent=2))
    text = bigger_camera.read_text(encoding="utf-8")
    bigger_camera.write_text(
        text.replace("width = 64\nheight = 64", f"width = {keys}\nheight = {keys}")
    )
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage)
    r = runner.invoke(app, ["run", "--resume", str(out)])
    said = _said(r)
    if not goes_on:
        assert r.exit_code != 0 and f"camera size: 64×64 → {keys}×{keys}" in said, said
        assert len(read_lp(out / "lights.lp")) == 1
        return
    assert r.exit_code == 0, said
    assert len(read_lp(out / "lights.lp")) == LIGHTS
    rig = json.loads((out / "manifest.json").read_text())["rig"]
    assert rig["identity"]["camera_size"] == "64×64"  # as the session began
