"""A dry run on the simulated dome rehearses the real teardown: a session closed before the
controller's teardown ran sends the simulated dome the all-off a dome on a port gets, and the
lights are said to be switched off only when an all-off reached it.

Why: the simulated dome had no link (``link_open`` False), so the session's close sent it no
all-off; a SIGTERM as the teardown began left its LED lit, and the run said "lights were
switched off" all the same (the sentence was fixed for every simulated dome)."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, opened_session_kept
from conftest import said as unwrapped
from typer.testing import CliRunner

import rti_rig.runtime.controller as controller
from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.app.usecases.safe_state import lights_state, safe_state_unsure
from rti_rig.cli import app
from rti_rig.runtime.session import SessionFolder


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_simulated_dome_lit_as_a_stop_cuts_the_teardown_is_switched_off_by_the_close(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen = opened_session_kept(monkeypatch)
    lit: list[int | None] = []
    real_held = controller._teardown_held

    def teardown_held(cancel):  # type: ignore[no-untyped-def]
        # an LED lit as the stop lands (as a stop during an image leaves it), then a real
        # SIGTERM where the controller's teardown sets its hold, in its place: the teardown
        # does not run (the controller catches a stop landing before its hold; this one cuts
        # it, as a stop the teardown cannot catch would): no timing
        dome = seen["opened"].rig.lighting.source
        dome.light(3)
        lit.append(dome.lit_now())
        signal.raise_signal(signal.SIGTERM)
        return real_held(cancel)

    monkeypatch.setattr(controller, "_teardown_held", teardown_held)
    real_record = SessionFolder.record_cut_end

    def record_cut_end(self: SessionFolder, reason: str, *more: list[str]) -> bool:
        lit.append(seen["opened"].rig.lighting.source.lit_now())  # off before the disk's fsync
        return real_record(self, reason, *more)

    monkeypatch.setattr(SessionFolder, "record_cut_end", record_cut_end)
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    said = unwrapped(r)
    assert r.exit_code == 143, said
    assert lit == [3, None], said
    dome = seen["opened"].rig.lighting.source
    # the all-off came on the open link (the session's close), before the dome was closed
    assert dome.history[-1][1] is None and not dome.link_open, dome.history[-3:]
    assert "Emergency stop (SIGTERM): lights were switched off." in said, said
    assert "Traceback" not in said and "teardown problem" not in said, said


def test_a_simulated_dome_left_lit_is_said_lit_not_switched_off() -> None:
    """What is said of the simulated dome follows what it was sent: an LED lit and no
    all-off after it is said as left lit (and unsure), never as switched off."""
    rig = build_rig(load_rig_config(CONFIGS / "simulated_dome.toml"))
    with rig:
        lighting = rig.lighting
        assert lights_state(rig) == "nothing was lit"
        lighting.connect()
        assert lighting.link_open is True
        lighting.source.light(5)
        assert lights_state(rig) == "LED 5 was left lit: no all-off reached the dome after it"
        assert safe_state_unsure(rig) is True
        lighting.close()  # as a real dome's driver: all off, then release
        assert lighting.link_open is False
        assert lights_state(rig) == "lights were switched off"
        assert safe_state_unsure(rig) is False
        lighting.safe()  # an all-off after the close reaches nothing: said as before
        assert lights_state(rig) == "lights were switched off"
