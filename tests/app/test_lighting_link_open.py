"""Every lighting a shipped config builds answers ``link_open`` (the Lighting protocol's).

Why: a session closed before the controller's teardown ran sends the all-off only where the
lights' link is open, and had asked with ``getattr(rig.lighting, "link_open", False)``: an
implementation without it (the arm) or a renamed attribute was silently taken for a closed
link. Now it is part of the protocol and each implementation says it."""

from __future__ import annotations

from pathlib import Path

import pytest

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config

REPO = Path(__file__).resolve().parents[2]


def kinds(config: str) -> tuple[str, ...]:
    """The lighting implementation each config is expected to build (so that every one of
    them is covered)."""
    if "arm" in config:
        return ("ArmLighting",)
    if "cceh" in config:
        return ("CameraTriggeredLighting",)
    return ("DomeLighting",)


@pytest.mark.parametrize(
    ("config", "open_when_connected"),
    [
        ("rig_configs/emulated_dome.toml", True),  # a serial port, open while connected
        ("rig_configs/simulated_dome.toml", True),  # connected: an all-off reaches it
        ("rig_configs/simulated_arm.toml", False),  # an arm's safe state is its teardown's
        ("tests/data/neuralrti_replay/dirs.lp", True),  # its simulated dome, connected
        ("rig_configs/emulated_cceh_rti.toml", False),  # stepped by the camera's flash signal
    ],
)
def test_a_built_rigs_lighting_says_whether_its_link_is_open(
    config: str, open_when_connected: bool
) -> None:
    rig = build_rig(load_rig_config(REPO / config))
    assert type(rig.lighting).__name__ in kinds(config), type(rig.lighting)
    with rig:
        lighting = rig.lighting
        assert lighting.link_open is False
        lighting.connect()
        try:
            assert lighting.link_open is open_when_connected
        finally:
            lighting.safe()
            lighting.close()
        assert lighting.link_open is False
