"""--auto-exposure checks several lights only where the lights' outputs are not known.

A dome that is not simulated and has no light calibration applied: its LEDs differ by tens of
percent, so the light nearest the zenith need not be the brightest (the shipped emulated card
dome clipped 7 of 48 images metered there). A simulated dome's LEDs are equal, a calibrated
one's evened out, an arm has one lamp: one light, as before, and no note.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, UnlimitedLighting, write_config

from rti_rig.app.config import load_rig_config, rig_geometry
from rti_rig.app.usecases.session import Note, fix_exposure
from rti_rig.planner.uniform import plan_uniform


class Metered(Exception):
    pass


#: Whether each metering asked for a test shot per lighting (a timed firmware's window).
shot_each: list[bool] = []


class FakeRig:
    """What fix_exposure reads of a rig before it meters."""

    def __init__(self, cfg: Path) -> None:
        self.loaded = load_rig_config(cfg)
        self.camera_config = self.loaded.config.camera
        self.lighting = UnlimitedLighting()


def _probes(cfg: Path, monkeypatch: pytest.MonkeyPatch, lights: int = 48) -> tuple[int, list[str]]:
    """How many lights fix_exposure asks the policy to meter at, and the notes it gives."""
    import rti_rig.runtime.exposure_policy as policy

    asked: list[int] = []
    shot_each.clear()

    def fake_fix(rig, schedule, meter, recheck, probes, **how):  # type: ignore[no-untyped-def]
        asked.append(probes if recheck is not None else 1)
        shot_each.append(how.get("shot_per_lighting", False))
        raise Metered

    monkeypatch.setattr(policy, "fix_session_exposure", fake_fix)
    rig = FakeRig(cfg)
    geometry = rig_geometry(rig.loaded)
    schedule = plan_uniform(geometry, min(lights, getattr(geometry, "count", lights)))
    notes: list[Note] = []
    with pytest.raises(Metered):
        fix_exposure(rig, schedule, 0.001, notes.append)  # type: ignore[arg-type]
    return asked[0], [n.text for n in notes]


def test_an_uncalibrated_dome_is_metered_at_six_lights_and_told_why(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    probes, notes = _probes(CONFIGS / "emulated_dome_card.toml", monkeypatch)
    assert probes == 6
    assert notes == [
        "This dome has no light calibration applied (rti-rig calibrate-lights): its LEDs may "
        "differ by tens of percent, so the light nearest the zenith need not be the brightest. "
        "Metering checks the 6 planned lights a level object receives most from: 5 more test "
        "shots than at one light, more where one is brighter (each about 1.1 s + the exposure: "
        "settle + readout + transfer)"
    ]
    # a session of fewer lights than that: every one of them, and no more
    probes, notes = _probes(CONFIGS / "emulated_dome_card.toml", monkeypatch, lights=3)
    assert probes == 3 and "Metering checks the 3 planned lights" in notes[0]


def test_a_timed_dome_is_told_each_test_shot_waits_out_a_window_of_its_own(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """RTIPy's LED goes dark 2 s after it lit, and a test shot takes about 1.1 s: a series
    under one lighting had its later shots dark. Each shot is lit again (asked of the policy),
    and the user is told so, and what it costs, before the lights come on."""
    probes, notes = _probes(CONFIGS / "emulated_rtipy.toml", monkeypatch)
    assert probes == 6 and shot_each == [True]
    assert "each test shot is taken under a window of its own" in notes[0], notes
    assert notes[-1].endswith("; each test shot also waits out an LED window of its own, 2 s)")
    # a dome whose LEDs stay lit until told: one lighting per light metered
    _probes(CONFIGS / "emulated_dome_card.toml", monkeypatch)
    assert shot_each == [False]


@pytest.mark.parametrize("config", ["simulated_dome.toml", "virtual_arm.toml", "calibrated"])
def test_equal_or_evened_out_lights_are_metered_at_one_light_without_a_note(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, config: str
) -> None:
    if config == "calibrated":
        text = (CONFIGS / "emulated_dome_card.toml").read_text(encoding="utf-8")
        text = text.replace('"example_dome_48.lp"', f'"{CONFIGS}/example_dome_48.lp"')
        factors = ", ".join(["0.9"] * 48)
        text = text.replace(
            'profile = "default"\n', f'profile = "default"\nintensity_correction = [{factors}]\n'
        )
        cfg = write_config(tmp_path, text)
    else:
        cfg = CONFIGS / config
    probes, notes = _probes(cfg, monkeypatch, lights=12)
    assert probes == 1 and not [n for n in notes if "Metering checks" in n]
