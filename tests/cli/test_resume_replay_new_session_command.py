"""A replay session whose acquisition changed since cannot be resumed, and is told to start a
new session with a command. That command had left out the session's options ("rti-rig run
ACQ/dirs.lp --out NEW, with the --lights and plan options this one began with", or no command
at all): pasted as printed, it shot every light of the acquisition in place of the session's
plan, adaptive choice or --lights N. It now repeats them, and runs as printed, from any
folder (a relative --plan had been repeated as typed; --allow-no-normals was not recorded, and
the command was refused the lights the session had been allowed), into a session asked for
what the first one was."""

from __future__ import annotations

import json
import re
import shlex
import shutil
from pathlib import Path
from typing import Any

import pytest
from conftest import cut_new_session, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay"
runner = CliRunner()
#: lights of the acquisition that cannot determine a normal (predicted error over 100°): a
#: session of them is refused without --allow-no-normals
RAKING = ("image01.jpg", "image09.jpg", "image13.jpg", "image69.jpg")


def _asked(manifest: dict[str, Any]) -> dict[str, Any]:
    """What a session's manifest records it was asked for (its layout options)."""
    adaptive = manifest.get("adaptive") or {}
    keys = ("max_lights", "design_lights", "until_error_deg", "min_lights", "objective")
    return {
        "method": manifest["schedule"]["method"],
        "provenance": {
            k: v for k, v in manifest["schedule"]["provenance"].items() if k != "plan_file"
        },
        "adaptive": {k: adaptive.get(k) for k in keys},
        "elevation": (adaptive.get("min_elevation_deg"), adaptive.get("max_elevation_deg")),
    }


def _cut_session(acq: Path, out: Path, **options: Any) -> None:
    """A replay of ``acq`` with ``options``, stopped after three images as Ctrl-C does."""
    from rti_rig.app.usecases.session import NewSessionRequest
    from rti_rig.runtime.controller import FinishReason

    result = cut_new_session(NewSessionRequest(acq / "dirs.lp", out, **options), after_step=2)
    assert result.finish_reason is FinishReason.CANCELLED


def _refused_resume_command(acq: Path, out: Path) -> list[str]:
    """The words of the new-session command a resume of ``out`` is refused with once an image
    of ``acq`` is replaced (as the shell splits it, after ``rti-rig run``)."""
    names = [e.name for e in read_lp(acq / "dirs.lp")]
    shutil.copy(acq / names[0], acq / names[-1])  # an image replaced since
    r = runner.invoke(app, ["run", "--resume", str(out)])
    text = said(r)
    assert r.exit_code == 2 and "Traceback" not in text, text
    command = re.search(r"\(rti-rig run ([^()]+)\)$", text)
    assert command, text
    return shlex.split(command.group(1))


@pytest.mark.parametrize(
    "options",
    [
        {"lights": 7, "min_elevation_deg": 20.0, "max_elevation_deg": 80.0},
        {"plan": "plan"},
        {"plan": "raking", "allow_no_normals": True},
        {"adaptive": True, "lights": 7, "min_elevation_deg": 10.0},
        {"until_error_deg": 4.0, "min_lights": 7},
    ],
    ids=["lights-band", "plan", "raking-plan-no-normals", "adaptive", "until-error"],
)
def test_the_new_session_a_changed_replay_is_told_to_start_runs_as_printed_with_its_options(
    tmp_path: Path, options: dict[str, Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # the plan is given by a relative path, as users type it
    acq, out = tmp_path / "acq", tmp_path / "S"
    shutil.copytree(ACQ, acq)
    if options.get("plan") == "raking":  # 4 lights of the acquisition with no normal
        lines = (ACQ / "dirs.lp").read_text().splitlines()[1:]
        raking = [line for line in lines if line.split()[0] in RAKING]
        Path("my plan.lp").write_text(f"{len(raking)}\n" + "\n".join(raking) + "\n")
        options = {**options, "plan": Path("my plan.lp")}
    elif "plan" in options:
        r = runner.invoke(
            app, ["plan", "--rig", str(acq / "dirs.lp"), "--lights", "6", "--out", "my plan.lp"]
        )
        assert r.exit_code == 0, r.output
        options = {"plan": Path("my plan.lp")}
    _cut_session(acq, out, **options)
    first = json.loads((out / "manifest.json").read_text())
    args = _refused_resume_command(acq, out)
    assert args[:2] == [str(acq / "dirs.lp"), "--out"], args
    new = Path(args[2])
    assert new.parent == out.parent and not new.exists(), args
    if "--plan" in args:  # the plan as a path that holds from any folder
        assert args[args.index("--plan") + 1] == str(tmp_path / "my plan.lp"), args

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # pasted in another folder than the session was started in
    r = runner.invoke(app, ["run", *args, "--no-verdict"])  # as printed
    assert r.exit_code == 0, r.output
    again = json.loads((new / "manifest.json").read_text())
    assert _asked(again) == _asked(first)
    if "until_error_deg" in options:  # the stop and its floor, as the first session's
        assert (again["adaptive"]["until_error_deg"], again["adaptive"]["min_lights"]) == (
            options["until_error_deg"],
            options["min_lights"],
        ), again["adaptive"]
    assert len((out / "journal.jsonl").read_text().splitlines()) == 3  # the first one kept


def test_the_new_session_command_names_the_plan_the_session_ran_from_any_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A session run with ``--plan plan.lp`` typed relative, resumed from another folder that
    holds a plan.lp of its own: the command had repeated ``--plan plan.lp`` as typed, which
    there names the other folder's plan (run as printed, it shot that plan's lights, not the
    session's). It names the session's plan by its absolute path."""
    acq, out = tmp_path / "acq", tmp_path / "S"
    shutil.copytree(ACQ, acq)
    first_dir, other_dir = tmp_path / "first", tmp_path / "other"
    for folder, lights in ((first_dir, "6"), (other_dir, "9")):
        folder.mkdir()
        monkeypatch.chdir(folder)
        r = runner.invoke(
            app, ["plan", "--rig", str(acq / "dirs.lp"), "--lights", lights, "--out", "plan.lp"]
        )
        assert r.exit_code == 0, r.output
    monkeypatch.chdir(first_dir)
    _cut_session(acq, out, plan=Path("plan.lp"))
    first = json.loads((out / "manifest.json").read_text())
    monkeypatch.chdir(other_dir)  # the resume, typed in another folder
    args = _refused_resume_command(acq, out)
    assert args[args.index("--plan") + 1] == str(first_dir / "plan.lp"), args
    r = runner.invoke(app, ["run", *args, "--no-verdict"])  # as printed, from there
    assert r.exit_code == 0, r.output
    again = json.loads((Path(args[2]) / "manifest.json").read_text())
    assert again["schedule"]["steps"] == first["schedule"]["steps"]


def test_a_session_from_before_the_flag_was_recorded_is_told_allow_no_normals_by_its_note(
    tmp_path: Path,
) -> None:
    """A raking-light session begun before ``--allow-no-normals`` was recorded in the
    provenance (its manifest holds only the note its lights were captured with, as
    e71079f2's do): the command had left the flag out, and pasted as printed it was refused
    the very lights the session had been allowed. The note says the flag was given."""
    acq, out = tmp_path / "acq", tmp_path / "S"
    shutil.copytree(ACQ, acq)
    lines = (ACQ / "dirs.lp").read_text().splitlines()[1:]
    raking = [line for line in lines if line.split()[0] in RAKING]
    plan = tmp_path / "raking.lp"
    plan.write_text(f"{len(raking)}\n" + "\n".join(raking) + "\n")
    _cut_session(acq, out, plan=plan, allow_no_normals=True)
    manifest_path = out / "manifest.json"
    manifest = json.loads(manifest_path.read_text())
    del manifest["schedule"]["provenance"]["allow_no_normals"]  # as an older manifest
    assert any("--allow-no-normals" in n for n in manifest["input_notes"]), manifest
    manifest_path.write_text(json.dumps(manifest))

    args = _refused_resume_command(acq, out)
    assert "--allow-no-normals" in args, args
    r = runner.invoke(app, ["run", *args, "--no-verdict"])  # as printed
    assert r.exit_code == 0, r.output
    again = json.loads((Path(args[2]) / "manifest.json").read_text())
    assert again["schedule"]["steps"] == manifest["schedule"]["steps"]
    assert again["schedule"]["provenance"]["allow_no_normals"] is True


def test_a_session_from_before_the_record_whose_lights_needed_no_flag_is_not_given_it(
    tmp_path: Path,
) -> None:
    """The other side: an older manifest with no such note (its lights determine normals)
    is not told a flag nothing shows it was given."""
    acq, out = tmp_path / "acq", tmp_path / "S"
    shutil.copytree(ACQ, acq)
    _cut_session(acq, out, lights=7)
    manifest_path = out / "manifest.json"
    manifest = json.loads(manifest_path.read_text())
    del manifest["schedule"]["provenance"]["allow_no_normals"]
    manifest_path.write_text(json.dumps(manifest))
    names = [e.name for e in read_lp(acq / "dirs.lp")]
    shutil.copy(acq / names[0], acq / names[-1])
    r = runner.invoke(app, ["run", "--resume", str(out)])
    text = said(r)
    assert r.exit_code == 2 and "--lights 7" in text, text
    assert "--allow-no-normals" not in text, text


def test_a_replay_session_resumed_as_dot_is_told_a_new_session_beside_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``run --resume .`` from inside a changed replay's session: its new-session folder is
    named from the session's absolute path (``S-new``). The folder had been made by adding
    to the name of ``.``, which has none: "unexpected ValueError", exit 1, no advice."""
    acq, out = tmp_path / "acq", tmp_path / "S"
    shutil.copytree(ACQ, acq)
    _cut_session(acq, out, lights=7)
    names = [e.name for e in read_lp(acq / "dirs.lp")]
    shutil.copy(acq / names[0], acq / names[-1])  # an image replaced since
    monkeypatch.chdir(out)
    r = runner.invoke(app, ["run", "--resume", "."])
    text = said(r)
    assert r.exit_code == 2 and "Traceback" not in text, text
    assert f"--out {tmp_path / 'S-new'} --lights 7" in text, text
