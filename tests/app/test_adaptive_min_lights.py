"""`rti-rig run RIG --until-error DEG --min-lights M`, through the front door.

A loose target is reached by the four starting lights: the session then has a normal map and
no RTI file (a PTM needs 6 lights, an HSH fit 5). ``--min-lights`` keeps the stop
from claiming the target before M lights, with the same choices a session without a target
makes; a resume restores the minimum from the manifest; a session that stops short of an RTI
file without it says so and how to ask for one; a minimum that cannot mean anything is refused
before anything is opened.
"""

from __future__ import annotations

import os
import shlex
import subprocess
from pathlib import Path

import pytest
from conftest import interrupted, journal, manifest, said
from typer.testing import CliRunner

from rti_rig.app.usecases.adaptive import FORMAT, FORMAT_MIN_LIGHTS
from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp
from rti_rig.runtime.controller import FinishReason

runner = CliRunner()

#: a target every estimate on the small dome is under (the upper estimates are a few degrees)
LOOSE = "89"


def _run(cfg: Path, out: Path, *extra: str):  # type: ignore[no-untyped-def]
    return runner.invoke(app, ["run", str(cfg), "--out", str(out), "--no-verdict", *extra])


def test_a_loose_target_stops_at_the_start_and_says_no_rti_file_follows(
    never_reached: tuple[Path, Path], tmp_path: Path
) -> None:
    cfg, _ = never_reached
    out = tmp_path / "s"
    r = _run(cfg, out, "--until-error", LOOSE)
    assert r.exit_code == 0, r.output
    assert manifest(out)["adaptive"]["result"]["lights_used"] == 4
    text = said(r)
    assert "a PTM needs 6 and an HSH fit needs 5" in text
    assert "without fit.ptm and fit.rti" in text
    assert "To get fit.ptm and fit.rti, start a session with --min-lights 6" in text
    # the session it names, as a command that runs pasted: the rig config, the options this
    # one had, a free folder beside it ("with --min-lights 6" had left the rest to find)
    more = tmp_path / "s-more"
    command = f"rti-rig run {cfg} --out {more} --until-error {LOOSE} --min-lights 6"
    lines = [line.rstrip() for line in r.output.splitlines()]  # one line: it pastes whole
    assert any(line.endswith(f"with --min-lights 6: {command}") for line in lines), r.output
    words = subprocess.run(
        ["bash", "-c", 'printf "%s\\0" ' + command], capture_output=True, check=True
    ).stdout.split(b"\0")[:-1]
    assert words[0] == b"rti-rig"
    again = runner.invoke(app, [os.fsdecode(w) for w in words[1:]])
    assert again.exit_code == 0, again.output
    assert len(read_lp(more / "lights.lp")) == 6
    assert "without fit.ptm" not in said(again), said(again)


@pytest.mark.parametrize("minimum", ["3", "4"])
def test_a_minimum_below_an_rti_file_s_lights_still_says_no_rti_file_follows(
    never_reached: tuple[Path, Path], tmp_path: Path, minimum: str
) -> None:
    """A minimum asked for had silenced the note: --min-lights 3 or 4 (the start is 4) stopped
    at 4 lights with nothing said of the fit.ptm and fit.rti that would not follow."""
    cfg, _ = never_reached
    out = tmp_path / "s"
    r = _run(cfg, out, "--until-error", LOOSE, "--min-lights", minimum)
    assert r.exit_code == 0, r.output
    assert manifest(out)["adaptive"]["result"]["lights_used"] == 4
    text = said(r)
    assert "without fit.ptm and fit.rti" in text, text
    assert "To get fit.ptm and fit.rti, start a session with --min-lights 6" in text, text


def test_the_advice_stays_within_the_session_s_maximum(
    never_reached: tuple[Path, Path], tmp_path: Path
) -> None:
    """With --lights 5 a minimum of 6 would be refused: the note offers 5 (an HSH fit) and
    says the PTM needs more than the session's maximum."""
    cfg, _ = never_reached
    out = tmp_path / "s"
    r = _run(cfg, out, "--until-error", LOOSE, "--lights", "5")
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "To get fit.rti, start a session with --min-lights 5" in text, text
    assert "fit.ptm needs more than this session's maximum of 5 lights" in text, text
    assert "--min-lights 6" not in text


def test_a_session_that_did_not_reach_its_target_gives_no_such_note(
    never_reached: tuple[Path, Path], tmp_path: Path
) -> None:
    """Capped at 5 lights short of its target: the stop says the target is not claimed, and
    nothing says it was reached."""
    cfg, _ = never_reached
    out = tmp_path / "s"
    r = _run(cfg, out, "--until-error", "1e-9", "--lights", "5")
    assert r.exit_code == 0, r.output
    result = manifest(out)["adaptive"]["result"]
    assert result["lights_used"] == 5 and result["target_claimed"] is False
    text = said(r)
    assert "the target is not claimed" in text and "reached the normal-error target" not in text
    # and what to do next: the command that shoots on without the cap, which pastes whole
    # (the run had ended "the target is not claimed" with no word of what to do)
    offered = manifest(out)["adaptive"]["candidates"]
    assert offered > 5
    lines = [line.rstrip() for line in r.output.splitlines()]
    (note,) = [line for line in lines if "was not reached in this session's maximum" in line]
    assert "--until-error 1e-09° was not reached in this session's maximum of 5 lights" in note
    assert f"with up to the {offered} lights a session on this rig can take" in note, note
    argv = shlex.split(note.rsplit(": ", 1)[1])
    assert argv == [
        "rti-rig", "run", str(cfg), "--out", str(tmp_path / "s-more"), "--until-error", "1e-09"
    ], note  # fmt: skip


def test_a_session_that_took_every_light_short_of_its_target_says_none_can_shoot_more(
    never_reached: tuple[Path, Path],
) -> None:
    """Every LED of the rig shot, the target not reached: no command is offered that would
    shoot the same lights again, and that is said."""
    _, out = never_reached
    text = (out.parent / "said.txt").read_text()
    assert "was not reached in this session's maximum of" in text, text
    assert "They are every light this rig offers here" in text, text
    assert "start a new session" not in text, text


def test_min_lights_holds_the_stop_until_m_lights_with_the_choices_of_no_target(
    never_reached: tuple[Path, Path], tmp_path: Path
) -> None:
    """The minimum binds (every decision before it already had its upper estimate under the
    target), the stop says it stopped at the minimum, lights.lp lists M lights, and the lights
    are those of the session that never reached its target (the target only stops)."""
    cfg, ref = never_reached
    out = tmp_path / "s"
    r = _run(cfg, out, "--until-error", LOOSE, "--min-lights", "7")
    assert r.exit_code == 0, r.output
    m = manifest(out)["adaptive"]
    assert m["min_lights"] == 7 and m["result"]["min_lights"] == 7
    assert m["format"] == FORMAT_MIN_LIGHTS != FORMAT  # an older build refuses it by name
    assert m["result"]["target_claimed"] is True
    steps = journal(out)
    assert m["result"]["lights_used"] == 7 == len(steps) == len(read_lp(out / "lights.lp"))
    for s in steps[4:]:
        assert s["decision"]["upper_error_deg"] <= float(LOOSE)  # the target alone would stop
        assert s["decision"]["held"] == "--min-lights 7"  # and the journal says why it did not
    assert "at the --min-lights 7 asked for" in m["result"]["stop"]["reason"]
    assert [s["led"] for s in steps] == [s["led"] for s in journal(ref)][:7]
    assert "--min-lights 9" not in said(r)  # asked for a minimum: no advice to ask for one


def test_an_interrupted_session_resumes_with_its_minimum(
    never_reached: tuple[Path, Path], tmp_path: Path
) -> None:
    """The minimum is in the manifest: the replay decides the steps on disk again under it
    (without it, the fifth step would have been a stop, and the resume refused), and the
    continuation stops at the same M."""
    cfg, ref = never_reached
    out = tmp_path / "cut"
    res = interrupted(cfg, out, 5, lights=None, until=float(LOOSE), min_lights=8)
    assert res.finish_reason is FinishReason.CANCELLED and len(journal(out)) == 6
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert [s["led"] for s in journal(out)] == [s["led"] for s in journal(ref)][:8]
    assert manifest(out)["adaptive"]["result"]["lights_used"] == 8


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--adaptive", "--lights", "8", "--min-lights", "6"], "with --lights 8 alone"),
        (["--min-lights", "6"], "goes with --until-error"),
        # no --lights given: the advice names what to add, not an option the user did not give
        (
            ["--adaptive", "--min-lights", "6"],
            "add --until-error (the target the stop claims, in degrees; 2 as the guide shows)",
        ),
        (["--until-error", "2", "--lights", "8", "--min-lights", "9"], "above --lights 8"),
        (["--until-error", "2", "--min-lights", "0"], "give a positive number"),
        (["--until-error", "2", "--min-lights", "13"], "this rig offers 12 lights"),
    ],
)
def test_a_minimum_that_cannot_mean_anything_is_refused_before_anything_is_written(
    never_reached: tuple[Path, Path], tmp_path: Path, args: list[str], message: str
) -> None:
    cfg, _ = never_reached
    out = tmp_path / "s"
    r = _run(cfg, out, *args)
    assert r.exit_code == 2, r.output
    assert message in said(r)
    assert not out.exists() or not any(out.iterdir())


def test_a_resume_refuses_a_new_minimum(never_reached: tuple[Path, Path]) -> None:
    _, ref = never_reached
    r = runner.invoke(app, ["run", "--resume", str(ref), "--min-lights", "6"])
    assert r.exit_code == 2 and "--min-lights 6, the session" in said(r), r.output


def test_a_dome_refuses_a_minimum_above_its_leds_before_opening_a_port(
    never_reached: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import rti_rig.app.compose as compose

    def no_rig(*_a, **_k):  # type: ignore[no-untyped-def]
        raise AssertionError("the rig was opened before the refusal")

    monkeypatch.setattr(compose, "build_rig", no_rig)
    cfg, _ = never_reached
    r = _run(cfg, tmp_path / "s", "--until-error", "2", "--min-lights", "13")
    assert r.exit_code == 2 and "this rig offers 12 lights" in said(r), r.output


def test_a_session_begun_before_the_minimum_existed_resumes_without_one(
    never_reached: tuple[Path, Path], tmp_path: Path
) -> None:
    """A format-8 manifest has no ``min_lights`` key: the resume decides as it began."""
    import json

    cfg, ref = never_reached
    out = tmp_path / "cut"
    interrupted(cfg, out, 5, lights=None, until=1e-9)
    m = json.loads((out / "manifest.json").read_text())
    assert m["adaptive"]["format"] == FORMAT
    del m["adaptive"]["min_lights"]
    (out / "manifest.json").write_text(json.dumps(m))
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert [s["led"] for s in journal(out)] == [s["led"] for s in journal(ref)]


@pytest.mark.parametrize("minimum", ["3", "4"])
def test_a_minimum_at_or_below_the_start_is_said_to_hold_nothing_before_anything_lights(
    never_reached: tuple[Path, Path], tmp_path: Path, minimum: str
) -> None:
    """--min-lights 3 or 4 was accepted and held nothing (the stop is first judged after the
    4 starting lights), with no word of it: the note says so before the first image, with the
    smallest minimum that holds the stop; --help says the same."""
    from rti_rig.planner.adaptive import START_LIGHTS

    cfg, _ = never_reached
    out = tmp_path / "s"
    r = _run(cfg, out, "--until-error", LOOSE, "--min-lights", minimum)
    assert r.exit_code == 0, r.output
    text = said(r)
    note = (
        f"--min-lights {minimum} holds nothing: an adaptive session shoots its {START_LIGHTS} "
        f"starting lights before its stop is first judged, so it never stops below "
        f"{START_LIGHTS}; the smallest --min-lights that holds its stop is {START_LIGHTS + 1}"
    )
    assert note in text, text
    assert text.index(note) < text.index("Rig ")  # before the capture's first line
    boxed = runner.invoke(app, ["run", "--help"]).output  # rich's box drawn round the help
    helped = " ".join(boxed.replace("│", " ").split())
    assert f"first judged after the {START_LIGHTS} starting lights" in helped, helped
    assert f"holds it from {START_LIGHTS + 1}" in helped, helped


def test_a_minimum_above_the_start_gives_no_such_note(
    never_reached: tuple[Path, Path], tmp_path: Path
) -> None:
    cfg, _ = never_reached
    r = _run(cfg, tmp_path / "s", "--until-error", LOOSE, "--min-lights", "5")
    assert r.exit_code == 0, r.output
    assert "holds nothing" not in said(r)


def test_an_arm_session_at_the_most_a_session_takes_is_not_told_to_start_another() -> None:
    """An arm's session stops at ARM_MAX_LIGHTS (100) whatever its rig offers (the virtual
    arm: 120): one that ran to 100 short of its target had been told to start a new session
    "with up to the 120 lights this rig offers", which stops at 100 again. It is told that
    no session on the rig shoots more; a session under that most is still given the command."""
    from rti_rig.app.usecases.adaptive import ARM_MAX_LIGHTS, short_of_target_note

    result = {
        "until_error_deg": 0.1,
        "target_claimed": False,
        "lights_used": ARM_MAX_LIGHTS,
        "max_lights": ARM_MAX_LIGHTS,
        "upper_error_deg": 0.5,
    }
    text = short_of_target_note(result, 120, lambda: "rti-rig run A --out B", ARM_MAX_LIGHTS)
    assert text is not None and "rti-rig run" not in text, text
    assert f"({ARM_MAX_LIGHTS} of the 120 it offers)" in text, text
    fewer = {**result, "lights_used": 40, "max_lights": 40}
    text = short_of_target_note(fewer, 120, lambda: "rti-rig run A --out B", ARM_MAX_LIGHTS)
    assert text is not None and f"up to the {ARM_MAX_LIGHTS} lights" in text, text
    assert text.endswith("rti-rig run A --out B"), text


@pytest.mark.parametrize("minimum", ["120", "130"])
def test_an_arm_refuses_a_minimum_above_the_most_a_session_takes(
    tmp_path: Path, minimum: str
) -> None:
    """The virtual arm offers 120 lights but a session without --lights takes at most 100
    (ARM_MAX_LIGHTS): --min-lights 120 had been accepted, 100 shot and the target claimed
    below the minimum, and 130 had been refused with advice to give that 120. Both are
    refused before anything moves, with a command that runs."""
    from rti_rig.app.usecases.adaptive import ARM_MAX_LIGHTS

    cfg = Path(__file__).resolve().parents[2] / "rig_configs" / "virtual_arm.toml"
    out = tmp_path / "s"
    r = _run(cfg, out, "--until-error", "1", "--min-lights", minimum)
    text = said(r)
    assert r.exit_code == 2, text
    assert f"--min-lights {minimum}: this adaptive session shoots at most {ARM_MAX_LIGHTS}" in text
    assert f"--until-error 1 --min-lights {ARM_MAX_LIGHTS}" in text and not out.exists()
