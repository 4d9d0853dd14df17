"""A rehearsed dome fault is refused where nothing would rehearse it, naming file and key.

``[[emulator.faults]]`` are keyed by the n-th command a serial dome's firmware emulator
receives, ``[[emulator.sync_faults]]`` by the n-th flash pulse of a camera-triggered dome. Each
kind was ignored on the other's rig: a ``reset`` on the camera-stepped cceh/rti dome (it has no
serial link) or a ``missed_pulse`` on the serial MiniRTI ran a clean ``check`` and said
``RESULT: PASS``, so the user believed a fault rehearsed that never happened.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()

RESET = '\n[[emulator.faults]]\nat_command = 3\nkind = "reset"\n'
MISSED = '\n[[emulator.sync_faults]]\nat_image = 2\nkind = "missed_pulse"\n'


@pytest.mark.parametrize(
    ("shipped", "extra", "words"),
    [
        (
            "emulated_cceh_rti.toml",
            RESET,
            "emulator.faults[0]: reset is a fault of a serial link's reply or command, and "
            "this dome (cceh-rti) has none: the camera's flash signal steps it. Rehearse its "
            "faults as [[emulator.sync_faults]]",
        ),
        (
            "simulated_dome.toml",
            RESET,
            "emulator.faults[0]: reset is rehearsed by an emulated dome's firmware on its "
            "serial link (backend = 'emulated' with a [dome.serial]), and this rig is not one",
        ),
        (
            "emulated_minirti.toml",
            MISSED,
            "emulator.sync_faults[0]: missed_pulse is a flash pulse of a camera-triggered "
            "dome ([dome.flash_sync], backend = 'emulated'), and no camera steps this rig's "
            "lights; rehearse a serial dome's faults as [[emulator.faults]]",
        ),
        (
            "hardware cceh",
            MISSED,
            "emulator.sync_faults[0]: missed_pulse is rehearsed by the emulated camera-triggered "
            "dome (backend = 'emulated'), and this rig's backend is 'hardware': nothing "
            "emulates its flash pulses; remove it",
        ),
        (
            "hardware cceh",
            RESET,
            "emulator.faults[0]: reset is a fault of a serial link's reply or command, and "
            "this dome (cceh-rti) has none: the camera's flash signal steps it. Nothing is "
            "rehearsed on backend = 'hardware': remove it",
        ),
        (
            "simulated_arm.toml",
            MISSED,
            "emulator.sync_faults[0]: missed_pulse is a flash pulse of a camera-triggered dome "
            "([dome.flash_sync], backend = 'emulated'), and an arm has none; remove it",
        ),
    ],
)
def test_a_fault_nothing_would_rehearse_is_refused(
    tmp_path: Path, shipped: str, extra: str, words: str
) -> None:
    """The case 'hardware cceh': the shipped emulated cceh/rti config made a real rig, as its
    header says (a rehearsal's fault left in it): its camera does step the dome, and the fault had
    been sent on to [[emulator.sync_faults]], refused there too."""
    config = tmp_path / "rig.toml"
    if shipped == "hardware cceh":
        text = (CONFIGS / "emulated_cceh_rti.toml").read_text()
        text = text.replace('backend = "emulated"', 'backend = "hardware"')
        text += '\n[camera.device]\nkind = "gphoto2"\n'
    else:
        text = (CONFIGS / shipped).read_text()
    config.write_text(text + extra)
    r = runner.invoke(app, ["check", str(config)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "Traceback" not in said, said
    assert "PASS" not in said
    assert f"{config}: {words}" in said, said


def test_the_dome_it_names_for_a_rehearsal_is_there_from_anywhere(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The refusal of a serial fault on a simulated dome names the emulated dome to rehearse it
    on: it had named ``rig_configs/emulated_dome.toml``, a path only a checkout's root has (an
    installed user, or one anywhere else, pasting it was told there is no such file). Run from
    another folder, every rig config the words name is a file there, as shell words."""
    import shlex

    config = tmp_path / "rig.toml"
    config.write_text((CONFIGS / "simulated_dome.toml").read_text() + RESET)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    r = runner.invoke(app, ["check", str(config)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "rehearse it on" in said, said
    named = [w.rstrip(",.;") for w in shlex.split(said.split("rehearse it on", 1)[1])]
    tomls = [w for w in named if w.endswith(".toml")]
    assert tomls and all(Path(w).is_file() for w in tomls), said
    assert any(Path(w).name == "emulated_dome.toml" for w in tomls), said


def test_the_rehearsal_it_advises_loads_when_followed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Followed as written (every file the refusal names copied into one folder, the fault
    added to the copied dome), the rehearsal config loads: the words had said to copy only
    emulated_dome.toml, whose ``lp_file = "example_dome_48.lp"`` is relative to its folder, so
    the copy was refused for a missing .lp."""
    import shlex
    import shutil

    from rti_rig.app.config import load_rig_config

    config = tmp_path / "rig.toml"
    config.write_text((CONFIGS / "simulated_dome.toml").read_text() + RESET)
    r = runner.invoke(app, ["check", str(config)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "rehearse it on" in said, said
    named = [w.rstrip(",.;") for w in shlex.split(said.split("rehearse it on", 1)[1])]
    files = [Path(w) for w in named if Path(w).is_file()]
    copies = tmp_path / "rehearsal"
    copies.mkdir()
    for f in files:
        shutil.copy(f, copies / f.name)
    copy = copies / "emulated_dome.toml"
    copy.write_text(copy.read_text() + RESET)
    monkeypatch.chdir(tmp_path)
    load_rig_config(copy)  # raises (a missing lp_file) where the .lp was not named
