"""A session's exposure is fixed from a test series at its brightest light, and recorded."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import SMALL_DOME, write_config
from typer.testing import CliRunner

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.exposure_policy import (
    brightest_step,
    fix_session_exposure,
    metering_start,
)

runner = CliRunner()


@pytest.mark.e2e
@pytest.mark.parametrize("exposure", ["0.05", "0.8"])  # sensible, and four stops too long
def test_auto_exposure_keeps_the_session_under_the_saturation_limit(
    tmp_path: Path, exposure: str
) -> None:
    cfg = write_config(
        tmp_path, SMALL_DOME.replace("exposure_s = 0.05", f"exposure_s = {exposure}")
    )
    out = tmp_path / "s"
    r = runner.invoke(
        app,
        [
            "run",
            str(cfg),
            "--out",
            str(out),
            "--lights",
            "8",
            "--auto-exposure",
            "--max-saturated",
            "0.002",
        ],
    )
    assert r.exit_code == 0, r.output
    m = json.loads((out / "manifest.json").read_text())
    chosen = m["schedule"]["provenance"]["exposure"]
    assert chosen["satisfied"] and chosen["measured_saturated_fraction"] <= 0.002
    assert {s["exposure_s"] for s in m["steps"]} == {chosen["exposure_s"]}
    assert max(s["saturated_fraction"] for s in m["steps"]) <= 0.002
    if exposure == "0.8":
        assert chosen["exposure_s"] < 0.8 and len(chosen["test_exposures_s"]) >= 2


def test_metering_lights_the_brightest_step_and_switches_it_off(tmp_path: Path) -> None:
    rig = build_rig(load_rig_config(write_config(tmp_path, SMALL_DOME)))
    schedule = plan_uniform(rig.geometry, 6)
    lit = []

    class Choice:
        exposure_s = 0.02

        def to_manifest(self) -> dict:
            return {"exposure_s": 0.02}

    def meter(camera, start_s: float) -> Choice:  # type: ignore[no-untyped-def]
        lit.append(rig.lighting.source.lit)  # type: ignore[attr-defined]
        return Choice()

    fixed = fix_session_exposure(rig, schedule, meter)
    assert lit == [schedule.steps[brightest_step(schedule)].led]
    assert rig.lighting.source.lit is None  # type: ignore[attr-defined]
    assert all(s.exposure_s == 0.02 for s in fixed.steps)
    assert fixed.provenance["exposure"]["metered_at_step"] == brightest_step(schedule) + 1


def test_a_teardown_that_fails_after_metering_is_an_error_not_silence(tmp_path: Path) -> None:
    """The metering leaves the lights as it found them or says it could not: a failed all-off
    must not be dropped on the floor (and the camera and lights are still closed)."""
    from rti_rig.core.errors import DeviceError

    rig = build_rig(load_rig_config(write_config(tmp_path, SMALL_DOME)))
    schedule = plan_uniform(rig.geometry, 6)
    closed = []
    real_close = rig.lighting.close

    class Choice:
        exposure_s = 0.02

        def to_manifest(self) -> dict:
            return {"exposure_s": 0.02}

    rig.lighting.safe = lambda emergency=False: ["all LEDs off: no reply"]  # type: ignore[method-assign]
    rig.lighting.close = lambda: (closed.append("lights"), real_close())  # type: ignore[method-assign]
    expected = r"metering could not make the rig safe \(all LEDs off: no reply\)"
    with pytest.raises(DeviceError, match=expected) as failed:
        fix_session_exposure(rig, schedule, lambda camera, start_s: Choice())
    assert closed == ["lights"]
    assert failed.value.teardown_failures == ["all LEDs off: no reply"]  # type: ignore[attr-defined]
    assert "port" not in str(failed.value)


def test_metering_unsafe_and_its_port_close_failing_both_named_and_carried(
    tmp_path: Path,
) -> None:
    """The all-off and then the port's close fail: the error had named the all-off alone and
    carried neither; both are named and carried (what the command line says and records)."""
    from rti_rig.core.errors import DeviceError

    rig = build_rig(load_rig_config(write_config(tmp_path, SMALL_DOME)))
    schedule = plan_uniform(rig.geometry, 6)
    said = "dome: its port did not close cleanly: [Errno 5] Input/output error."
    rig.lighting.safe = lambda emergency=False: ["all LEDs off: no reply"]  # type: ignore[method-assign]
    rig.lighting.port_close_failure = lambda: said  # type: ignore[method-assign]

    class Choice:
        exposure_s = 0.02

        def to_manifest(self) -> dict:
            return {"exposure_s": 0.02}

    with pytest.raises(DeviceError) as failed:
        fix_session_exposure(rig, schedule, lambda camera, start_s: Choice())
    assert "(all LEDs off: no reply), and its lights' port did not close cleanly" in str(
        failed.value
    )
    carried = failed.value.teardown_failures  # type: ignore[attr-defined]
    assert carried == ["all LEDs off: no reply", f"port close: {said}"]


def test_a_port_that_did_not_close_after_metering_is_recorded_not_called_unsafe(
    tmp_path: Path,
) -> None:
    """Metering's lights closed at its end (a simulated dome is never held open), their port's
    close failing: kept in the exposure's evidence, which the session's manifest holds (it had
    been in no record), and no reason to refuse the metering (its all-off went through)."""
    rig = build_rig(load_rig_config(write_config(tmp_path, SMALL_DOME)))
    schedule = plan_uniform(rig.geometry, 6)
    said = "dome: its port did not close cleanly: [Errno 5] Input/output error."
    rig.lighting.port_close_failure = lambda: said  # type: ignore[method-assign]

    class Choice:
        exposure_s = 0.02

        def to_manifest(self) -> dict:
            return {"exposure_s": 0.02}

    fixed = fix_session_exposure(rig, schedule, lambda camera, start_s: Choice())
    assert fixed.provenance["exposure"]["teardown_failures"] == [f"port close: {said}"]
    assert not rig.lighting.link_open


def test_a_stop_during_metering_carries_what_the_teardown_could_not_do(tmp_path: Path) -> None:
    """A Ctrl-C while metering had dropped the teardown's failures, and the user was told an
    all-off had been sent."""
    rig = build_rig(load_rig_config(write_config(tmp_path, SMALL_DOME)))
    schedule = plan_uniform(rig.geometry, 6)
    rig.lighting.safe = lambda emergency=False: ["all LEDs off: no reply"]  # type: ignore[method-assign]

    def meter(camera, start_s: float):  # type: ignore[no-untyped-def]
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as stopped:
        fix_session_exposure(rig, schedule, meter)
    assert stopped.value.teardown_failures == ["all LEDs off: no reply"]  # type: ignore[attr-defined]


#: ``rti-rig run`` in a process of its own, on an emulated dome whose board is recorded: Ctrl-C
#: while metering the second light, and a second Ctrl-C ("stop at once") as metering's teardown
#: begins; the LEDs the board has lit are printed at the end.
_DOUBLE_CTRL_C = """
import os, signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)
import rti_rig.simulator.domes as domes
boards, board_for = [], domes.board_for
def recorded(*a, **k):
    boards.append(board_for(*a, **k))
    return boards[-1]
domes.board_for = recorded
import rti_rig.drivers.cameras.exposure as exposure
recheck = exposure.recheck_exposure
def ctrl_c(*a, **k):
    os.kill(os.getpid(), signal.SIGINT)
    return recheck(*a, **k)
exposure.recheck_exposure = ctrl_c
from rti_rig.runtime.lighting import DomeLighting
safe = DomeLighting.safe
def ctrl_c_again(self, *a, **k):
    os.kill(os.getpid(), signal.SIGINT)
    return safe(self, *a, **k)
DomeLighting.safe = ctrl_c_again
from rti_rig.launch import main
sys.argv = ["rti-rig", *sys.argv[1:]]
try:
    main()
finally:
    print("LIT at exit:", [sorted(b.lit) for b in boards], flush=True)
"""


@pytest.mark.pty
@pytest.mark.skipif(__import__("sys").platform != "linux", reason="pty semantics on Linux")
def test_a_second_ctrl_c_does_not_cut_meterings_all_off_short(tmp_path: Path) -> None:
    """Ctrl-C twice while `--auto-exposure` metered on an uncalibrated dome (six lights, an
    all-off between two): the second cut metering's all-off short, left an LED lit, and the
    all-off between two metered lights was then said of the lights ("acknowledged by the dome:
    lights are off"). The second stop is held until the teardown is done."""
    import subprocess
    import sys

    cfg = Path(__file__).resolve().parents[2] / "rig_configs" / "emulated_nichlock.toml"
    out = tmp_path / "s"
    proc = subprocess.run(
        [
            sys.executable,
            "-c",
            _DOUBLE_CTRL_C,
            "run",
            str(cfg),
            "--out",
            str(out),
            "--auto-exposure",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    said = " ".join((proc.stdout + proc.stderr).split())
    assert proc.returncode == 130, said
    assert "LIT at exit: [[]]" in said, said  # the emulated board: every LED dark
    assert "metering was stopped, and then: all-off sent and acknowledged" in said, said
    assert not out.exists()


class _FramePeriodCamera:
    """A camera whose longest exposure is its frame period (a 20 fps UVC camera's 0.05 s)."""

    name = "uvc-camera"

    def longest_exposure_s(self) -> tuple[float, str]:
        return 0.05, "the frame period at 20 fps, 0.05 s"


@pytest.mark.parametrize(
    "cap",
    [
        (0.03, "[camera] max_exposure_s = 0.03 s"),
        (0.03, "0.03 s, the longest shot an LED lit at most max_on_s allows"),
    ],
)
def test_a_metering_start_above_both_limits_names_the_one_that_set_it(cap) -> None:
    """``[camera] exposure_s = 0.2`` above both the camera's longest (its frame period,
    0.05 s) and the metering's own cap (0.03 s): the metering starts at 0.03 s, set by the
    metering's cap, but the note blamed the frame period. It names what set the start.
    (``rti-rig run`` refuses an exposure_s above ``[camera] max_exposure_s`` when the config
    loads; the lit-time cap reaches this the same way.)"""
    start, note = metering_start(_FramePeriodCamera(), 0.2, ((0.0001, "[camera] min"), cap))
    assert start == pytest.approx(0.03)
    assert note == (
        f"[camera] exposure_s = 0.2 s is longer than the metering may go ({cap[1]}): the "
        "metering started at 0.03 s instead"
    ), note
    # the frame period setting the start is still said as the camera's
    start, note = metering_start(_FramePeriodCamera(), 0.2, ((0.0001, "[camera] min"), (1, "x")))
    assert start == pytest.approx(0.05)
    assert note is not None and "can take (the frame period at 20 fps, 0.05 s)" in note, note
