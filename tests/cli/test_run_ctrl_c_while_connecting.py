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
from rti_rig.runtime.lighting import ArmLighting

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
