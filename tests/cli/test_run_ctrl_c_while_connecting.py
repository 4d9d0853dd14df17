"""A first Ctrl-C while ``run`` connects the rig, before any step began, is said as that.

Found by a front-door audit: on an arm whose servos do not answer at the configured rate, the
connect scans the other rates (up to about 10 s); a Ctrl-C there was told "Stopping after this
image (Ctrl-C again to stop at once)…", with no image under way. The stop itself is unchanged:
the run stops before its first step once the rig is connected ('Session cancelled.').
"""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from conftest import said as unwrapped
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.runtime.controller import CancelToken
from rti_rig.runtime.lighting import ArmLighting
from rti_rig.simulator.sim_camera import SimulatedCamera

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")


def test_a_ctrl_c_as_the_arm_connects_is_not_said_as_after_this_image(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_connect = ArmLighting.connect

    def connect(self: ArmLighting) -> None:
        os.kill(os.getpid(), signal.SIGINT)  # the user's Ctrl-C, as the connect begins
        real_connect(self)

    monkeypatch.setattr(ArmLighting, "connect", connect)
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "virtual_arm.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    said = unwrapped(r)
    assert "Stopping after this image" not in said, said
    assert "Stopping before any image is taken: the rig is being connected" in said, said
    assert "Session cancelled." in said and "Nothing was captured: " in said, said
    assert r.exit_code == 130, said
    assert not any(out.glob("image_*"))


def _ctrl_c() -> None:
    os.kill(os.getpid(), signal.SIGINT)  # the user's Ctrl-C, here and now


def _camera_connect(monkeypatch: pytest.MonkeyPatch) -> None:
    real = SimulatedCamera.connect

    def connect(self: SimulatedCamera) -> None:
        _ctrl_c()
        real(self)

    monkeypatch.setattr(SimulatedCamera, "connect", connect)


def _card_listed(monkeypatch: pytest.MonkeyPatch) -> None:
    def list_card(self: SimulatedCamera, say: object) -> None:  # a card camera's listing
        _ctrl_c()

    monkeypatch.setattr(SimulatedCamera, "list_card", list_card, raising=False)


def _paused_before_the_first(monkeypatch: pytest.MonkeyPatch) -> None:
    real_connect = SimulatedCamera.connect
    real_wait = CancelToken.wait_while_paused

    def connect(self: SimulatedCamera) -> None:  # a SIGUSR1 as the rig connects: paused
        os.kill(os.getpid(), signal.SIGUSR1)
        real_connect(self)

    def wait_while_paused(self: CancelToken, poll_s: float = 0.05) -> None:
        _ctrl_c()  # while the pause waits
        real_wait(self, poll_s)

    monkeypatch.setattr(SimulatedCamera, "connect", connect)
    monkeypatch.setattr(CancelToken, "wait_while_paused", wait_while_paused)


@pytest.mark.parametrize(
    ("arrange", "doing"),
    [
        (_camera_connect, "the camera is being connected"),
        (_card_listed, "the camera's card is being listed"),
        (_paused_before_the_first, "the capture is paused before its first image"),
    ],
    ids=["camera-connect", "card-listing", "paused-before-the-first-step"],
)
def test_a_ctrl_c_before_the_first_step_says_what_is_under_way(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, arrange: object, doing: str
) -> None:
    """Before, each was told "the rig is being connected" (said of any wait before the first
    step), though the rig's lights had answered and the wait was the camera's or a pause's."""
    arrange(monkeypatch)  # type: ignore[operator]
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    said = unwrapped(r)
    assert f"Stopping before any image is taken: {doing} (Ctrl-C again" in said, said
    stop = said.split("Stopping before any image is taken: ", 1)[1]  # a pause says its own
    assert "being connected" not in stop.replace(doing, ""), said
    assert "Session cancelled." in said and "Nothing was captured: " in said, said
    assert r.exit_code == 130, said
    assert not any(out.glob("image_*"))


def _pause_at_camera_connect(monkeypatch: pytest.MonkeyPatch) -> None:
    """A SIGUSR1 as the camera connects (the run pauses before its first step), then a Ctrl-C
    while the pause waits: the run ends there, as a user's would."""
    real_connect = SimulatedCamera.connect
    real_wait = CancelToken.wait_while_paused

    def connect(self: SimulatedCamera) -> None:
        os.kill(os.getpid(), signal.SIGUSR1)
        real_connect(self)

    def wait_while_paused(self: CancelToken, poll_s: float = 0.05) -> None:
        _ctrl_c()
        real_wait(self, poll_s)

    monkeypatch.setattr(SimulatedCamera, "connect", connect)
    monkeypatch.setattr(CancelToken, "wait_while_paused", wait_while_paused)


def test_a_pause_before_the_first_step_says_what_is_under_way(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Before, a SIGUSR1 as the camera connected was told "Pausing after this image", with no
    image under way: the pause takes hold before image 1, once the rig is connected."""
    _pause_at_camera_connect(monkeypatch)
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    said = unwrapped(r)
    assert "Pausing after this image" not in said, said
    assert (
        "Pausing before image 1 is taken: the camera is being connected; SIGUSR1 again resumes."
        in said
    ), said
    assert "Paused before image 1: " in said, said
    assert (
        "Stopping before any image is taken: the capture is paused before its first image" in said
    )
    assert r.exit_code == 130, said
    assert not any(out.glob("image_*"))


@pytest.fixture(scope="module")
def two_of_six(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A session of 6 lights on the emulated dome, cut once its second image is in."""
    from conftest import cut_new_session

    from rti_rig.app.usecases.session import NewSessionRequest

    out = tmp_path_factory.mktemp("cut") / "s"
    cut_new_session(NewSessionRequest(CONFIGS / "emulated_dome.toml", out, lights=6), 1)
    assert sorted(p.name for p in out.glob("image_*.jpg")) == ["image_001.jpg", "image_002.jpg"]
    return out


@pytest.mark.parametrize("paused", [False, True], ids=["ctrl-c", "paused-then-ctrl-c"])
def test_a_resumed_run_stopped_before_its_first_new_step_says_its_images_are_kept(
    two_of_six: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, paused: bool
) -> None:
    """Before, a resumed run's Ctrl-C as the rig connected was told "Stopping before any image
    is taken" (and its pause "Pausing after this image", then "paused before its first
    image") of a session that holds two: the next image is the third, the two are kept."""
    import shutil

    session = tmp_path / "s"
    shutil.copytree(two_of_six, session)
    if paused:
        _pause_at_camera_connect(monkeypatch)
    else:
        _camera_connect(monkeypatch)
    r = CliRunner().invoke(app, ["run", "--resume", str(session), "--no-verdict"])
    said = unwrapped(r)
    doing = "the capture is paused before image 3" if paused else "the camera is being connected"
    assert (
        "Stopping before image 3 is taken (the 2 already in the session are kept): "
        f"{doing} (Ctrl-C again" in said
    ), said
    assert "any image" not in said and "first image" not in said, said
    if paused:
        assert "Pausing before image 3 is taken: the camera is being connected;" in said, said
        assert "Pausing after this image" not in said, said
    assert r.exit_code == 130, said
    assert sorted(p.name for p in session.glob("image_*.jpg")) == [
        "image_001.jpg",
        "image_002.jpg",
    ]
