"""A lab's script resumes with the line that began the session: ``rti-rig run RIG --out S
--lights N`` and, if that fails, the same line with ``--resume S``.

Before: the identical request was refused as a different one would be ("drop --out,
--lights", exit 2); a resume of a session that had completed every step, every image intact,
was an error (exit 2) with no next step; and a run that never recorded its end was marked
``crashed`` by the next resume, a cause nobody had established (it may have been killed, a
power cut or a full disk).
"""

from __future__ import annotations

import hashlib
import json
import math
import shlex
import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS, cut_new_session, interrupted, manifest, said
from typer.testing import CliRunner

from rti_rig.app.usecases.session import NewSessionRequest
from rti_rig.cli import app
from rti_rig.runtime.controller import FinishReason

runner = CliRunner()
DOME = CONFIGS / "simulated_dome.toml"


def tree(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` and its checksum: what a refusal must leave as it was."""
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


@pytest.fixture(scope="module")
def stopped(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A session of ``--lights 8`` on the shipped simulated dome, stopped after 3 images."""
    out = tmp_path_factory.mktemp("line") / "s"
    run = cut_new_session(NewSessionRequest(DOME, out, lights=8), after_step=2)
    assert run.finish_reason is FinishReason.CANCELLED
    return out


def copy_of(session: Path, tmp_path: Path) -> Path:
    out = tmp_path / "s"
    shutil.copytree(session, out)
    return out


def test_the_line_the_session_began_with_continues_it(stopped: Path, tmp_path: Path) -> None:
    out = copy_of(stopped, tmp_path)
    kept = {k: v for k, v in tree(out).items() if k.startswith(("image_", "linear/"))}
    line = ["run", str(DOME), "--out", str(out), "--lights", "8", "--no-verdict"]
    r = runner.invoke(app, [*line, "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert "3 of 8 images verified on disk" in said(r)
    assert manifest(out)["runner"]["finish_reason"] == "completed"
    after = tree(out)
    assert all(after[name] == digest for name, digest in kept.items())  # nothing overwritten
    # the same line once more, on the session now complete: said so, with the next step
    r = runner.invoke(app, [*line, "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert "this session is complete: all 8 steps were captured" in said(r)
    assert f"Next: rti-rig fit {out} --out {out}-fit" in said(r)
    assert tree(out) == after


@pytest.mark.parametrize(
    ("options", "named"),
    [
        (["--lights", "9"], "--lights 9 gives 9 lights; the session has 8"),
        (
            ["--lights", "8", "--min-elevation-deg", "10"],
            "--min-elevation-deg 10, the session 0",
        ),
        (["--lights", "8", "--allow-no-normals"], "--allow-no-normals given; the session had not"),
        (["--adaptive", "--lights", "8"], "the session ran a planned layout; this asks for an"),
        (
            ["--lights", "8", "--max-saturated", "0.01"],
            "--max-saturated 0.01 given; the session was not metered",
        ),
    ],
)
def test_another_request_is_refused_naming_what_differs(
    stopped: Path, tmp_path: Path, options: list[str], named: str
) -> None:
    out = copy_of(stopped, tmp_path)
    before = tree(out)
    r = runner.invoke(app, ["run", str(DOME), "--out", str(out), "--resume", str(out), *options])
    assert r.exit_code == 2, r.output
    assert named in said(r)
    assert "It began with --lights 8" in said(r)
    assert f"rti-rig run --resume {out})" in said(r)
    assert tree(out) == before
    # the request as a new session, a command that runs pasted: the rig, the options asked and
    # a free folder beside the session ("start a new session in a new --out" had been said)
    new = said(r).split("with your options in place of its own, start a new session: ", 1)[1]
    assert new.startswith(f"rti-rig run {DOME} ") and new.endswith(f"--out {tmp_path / 's-2'}")
    words = shlex.split(new)
    assert [w for w in options if w not in words] == [], new
    if options == ["--lights", "9"]:  # pasted, it runs (one case: each is the same command)
        r = runner.invoke(app, [*words[1:], "--no-verdict"])
        assert r.exit_code == 0, r.output
        assert len(list((tmp_path / "s-2").glob("image_*.jpg"))) == 9


def test_another_out_folder_is_refused(stopped: Path, tmp_path: Path) -> None:
    out = copy_of(stopped, tmp_path)
    before = tree(out)
    other = tmp_path / "other"
    r = runner.invoke(app, ["run", str(DOME), "--out", str(other), "--resume", str(out)])
    assert r.exit_code == 2, r.output
    assert "are two folders" in said(r) and "drop --out" in said(r)
    assert tree(out) == before and not other.exists()


def test_another_rig_given_with_the_sessions_own_options_is_refused_as_another_rig(
    stopped: Path, tmp_path: Path
) -> None:
    """The session's own options on another rig: the rig is named, not the options (its
    layout compared with the session's had been blamed on --lights 8, the session's own, with
    the advice to give those very options)."""
    out = copy_of(stopped, tmp_path)
    before = tree(out)
    arm = CONFIGS / "simulated_arm.toml"
    line = ["run", str(arm), "--out", str(out), "--lights", "8", "--resume", str(out)]
    r = runner.invoke(app, line)
    assert r.exit_code == 2, r.output
    assert "is a rig of kind 'arm', and this session was begun on one of kind 'dome'" in said(r)
    assert "asks for another session" not in said(r)
    assert tree(out) == before


def test_the_same_plan_continues_its_session_however_its_numbers_are_written(
    tmp_path: Path,
) -> None:
    plan = tmp_path / "plan.lp"
    r = runner.invoke(
        app,
        ["plan", "--rig", str(DOME), "--lights", "10", "--method", "uniform", "--out", str(plan)],
    )
    assert r.exit_code == 0, r.output
    lines = plan.read_text().splitlines()
    rounded = tmp_path / "rounded.lp"  # another program's copy: four decimals
    rounded.write_text(
        "\n".join(
            [lines[0]]
            + [
                f"{w[0]} " + " ".join(f"{float(v):.4f}" for v in w[1:])
                for w in map(str.split, lines[1:])
            ]
        )
        + "\n"
    )
    swapped = tmp_path / "swapped.lp"  # lights 3 and 4 exchanged: another session
    a, b = lines[3].split(), lines[4].split()
    swapped.write_text(
        "\n".join([*lines[:3], " ".join([a[0], *b[1:]]), " ".join([b[0], *a[1:]]), *lines[5:]])
        + "\n"
    )
    out = tmp_path / "s"
    run = cut_new_session(NewSessionRequest(DOME, out, plan=plan), after_step=3)
    assert run.finish_reason is FinishReason.CANCELLED
    before = tree(out)
    r = runner.invoke(app, ["run", str(DOME), "--resume", str(out), "--plan", str(swapped)])
    assert r.exit_code == 2, r.output
    assert "its light 3 is LED" in said(r) and f"It began with --plan {plan}" in said(r)
    assert tree(out) == before
    r = runner.invoke(
        app, ["run", str(DOME), "--resume", str(out), "--plan", str(rounded), "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    assert "4 of 10 images verified on disk" in said(r)


def rewritten(plan: Path, to: Path, decimals: int, turn_light: int | None = None) -> Path:
    """``plan`` written again with ``decimals`` decimals, light ``turn_light`` (1-based)
    turned 1° in azimuth."""
    lines = plan.read_text().splitlines()
    out = [lines[0]]
    for k, words in enumerate(map(str.split, lines[1:]), start=1):
        x, y, z = (float(v) for v in words[1:4])
        if k == turn_light:
            c, s = math.cos(math.radians(1.0)), math.sin(math.radians(1.0))
            x, y = c * x - s * y, s * x + c * y
        out.append(f"{words[0]} {x:.{decimals}f} {y:.{decimals}f} {z:.{decimals}f}")
    to.write_text("\n".join(out) + "\n")
    return to


def test_an_arm_plan_is_compared_light_by_light_within_its_numbers(tmp_path: Path) -> None:
    arm = CONFIGS / "simulated_arm.toml"
    plan = tmp_path / "plan.lp"
    r = runner.invoke(
        app, ["plan", "--rig", str(arm), "--lights", "8", "--method", "uniform", "--out", str(plan)]
    )
    assert r.exit_code == 0, r.output
    out = tmp_path / "s"
    run = cut_new_session(NewSessionRequest(arm, out, plan=plan), after_step=2)
    assert run.finish_reason is FinishReason.CANCELLED
    before = tree(out)
    turned = rewritten(plan, tmp_path / "turned.lp", 6, turn_light=5)
    r = runner.invoke(app, ["run", str(arm), "--resume", str(out), "--plan", str(turned)])
    assert r.exit_code == 2, r.output
    assert f"--plan {turned}: its light 5 is az" in said(r), r.output
    assert tree(out) == before
    rounded = rewritten(plan, tmp_path / "rounded.lp", 4)
    line = ["run", str(arm), "--resume", str(out), "--plan", str(rounded), "--no-verdict"]
    r = runner.invoke(app, line)
    assert r.exit_code == 0, r.output
    assert "3 of 8 images verified on disk" in said(r)


def test_an_arm_band_that_moves_the_lights_is_named_not_the_sessions_own_lights(
    tmp_path: Path,
) -> None:
    """On an arm a band moves every light: the refusal had named ``--lights 6`` (the
    session's own) and its first light, not the ``--min-elevation-deg`` that differs."""
    arm = CONFIGS / "simulated_arm.toml"
    out = tmp_path / "s"
    run = cut_new_session(NewSessionRequest(arm, out, lights=6), after_step=2)
    assert run.finish_reason is FinishReason.CANCELLED
    before = tree(out)
    line = ["run", str(arm), "--out", str(out), "--lights", "6", "--resume", str(out)]
    r = runner.invoke(app, [*line, "--min-elevation-deg", "30"])
    assert r.exit_code == 2, r.output
    assert "--min-elevation-deg 30, the session 0" in said(r), r.output
    assert "its light 1 is" not in said(r)
    assert tree(out) == before


def test_an_adaptive_session_continues_with_its_own_line(tmp_path: Path) -> None:
    out = tmp_path / "s"
    run = interrupted(DOME, out, after_step=4, lights=7)
    assert run.finish_reason is FinishReason.CANCELLED
    before = tree(out)
    line = ["run", str(DOME), "--out", str(out), "--resume", str(out), "--no-verdict"]
    r = runner.invoke(app, [*line, "--adaptive", "--lights", "8"])
    assert r.exit_code == 2, r.output
    assert "--lights 8, the session 7" in said(r) and "It began with --adaptive --lights 7" in said(
        r
    )
    assert tree(out) == before
    # a limit no metering reads: refused, as a new adaptive session refuses it
    r = runner.invoke(app, [*line, "--adaptive", "--lights", "7", "--max-saturated", "0.01"])
    assert r.exit_code == 2, r.output
    assert "--max-saturated 0.01: an adaptive session is not metered" in said(r)
    assert tree(out) == before
    r = runner.invoke(app, [*line, "--adaptive", "--lights", "7"])
    assert r.exit_code == 0, r.output
    assert "5 of 7 images verified on disk" in said(r)
    r = runner.invoke(app, [*line, "--adaptive", "--lights", "7"])
    assert r.exit_code == 0, r.output
    assert "this session is complete" in said(r) and "Next: rti-rig fit" in said(r)
    # another request of the finished session: it is not "continued as it began" (that
    # resume answers "complete, nothing to resume"), it is said complete, with the new session
    # and the fit
    before = tree(out)
    r = runner.invoke(app, [*line, "--adaptive", "--lights", "9"])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "It began with --adaptive --lights 7 and is complete" in text, text
    assert "to continue it as it began" not in text and "rti-rig fit" in text
    assert "start a new session: rti-rig run" in text and "--adaptive --lights 9" in text
    assert tree(out) == before


def test_a_metered_session_continues_with_its_own_metering_options(tmp_path: Path) -> None:
    out = tmp_path / "s"
    request = NewSessionRequest(DOME, out, lights=8, auto_exposure=True, max_saturated=0.002)
    assert cut_new_session(request, after_step=2).finish_reason is FinishReason.CANCELLED
    before = tree(out)
    line = ["run", str(DOME), "--out", str(out), "--resume", str(out), "--lights", "8"]
    for options, named in (
        ([], "--auto-exposure not given; the session's exposure was metered"),
        (["--auto-exposure"], "--max-saturated not given (0.001), the session 0.002"),
    ):
        r = runner.invoke(app, [*line, *options])
        assert r.exit_code == 2, r.output
        assert named in said(r), r.output
        assert "It began with --lights 8 --auto-exposure --max-saturated 0.002" in said(r)
        assert tree(out) == before
    r = runner.invoke(app, [*line, "--auto-exposure", "--max-saturated", "0.002", "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "3 of 8 images verified on disk" in said(r)
    assert "Exposure fixed" not in said(r)  # the session's exposure, not metered again


def test_a_complete_session_with_an_image_changed_is_still_refused(
    stopped: Path, tmp_path: Path
) -> None:
    out = copy_of(stopped, tmp_path)
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    (out / "image_002.jpg").write_bytes(b"not the image captured")
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 2, r.output
    assert "is missing or changed since capture (image_002)" in said(r)
    assert "--reshoot-lost" in said(r) and "is complete" not in said(r)


def test_a_run_that_recorded_no_end_is_marked_unrecorded_not_crashed(
    stopped: Path, tmp_path: Path
) -> None:
    out = copy_of(stopped, tmp_path)
    # as a kill -9, a power cut or a full disk leaves it: the run's end never written
    m = manifest(out)
    m["runner"] = {"state": "running", "finish_reason": None}
    m["runs"][-1] = {k: v for k, v in m["runs"][-1].items() if k in ("started_at", "software")}
    (out / "manifest.json").write_text(json.dumps(m))
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    runs = manifest(out)["runs"]
    assert [run.get("finish_reason") for run in runs] == ["unrecorded", "completed"]


def test_a_complete_session_without_its_lights_lp_names_export_lp_before_fit(
    stopped: Path, tmp_path: Path
) -> None:
    """Its images are all there, so it is complete; but fit refuses a session folder without
    its lights.lp, so the next step named is the export-lp that writes it, then fit (it had
    named fit alone, which then failed)."""
    out = copy_of(stopped, tmp_path)
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    (out / "lights.lp").unlink()
    before = tree(out)
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "this session is complete" in said(r) and "only its lights.lp is missing" in said(r)
    assert f"Next: rti-rig export-lp {out} --out {out / 'lights.lp'} writes it" in said(r)
    assert tree(out) == before


def test_a_completed_sessions_journal_rebuild_refuses_the_options_it_cannot_check(
    stopped: Path, tmp_path: Path
) -> None:
    """The rebuild of a completed session's journal opens no rig, so the options given with it
    are compared with nothing: refused, the folder as it was (they had gone on unsaid)."""
    out = copy_of(stopped, tmp_path)
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    (out / "journal.jsonl").unlink()
    before = tree(out)
    line = ["run", "--resume", str(out), "--rebuild-journal"]
    r = runner.invoke(app, [*line, "--lights", "9", "--auto-exposure"])
    assert r.exit_code == 2, r.output
    assert "so --lights, --auto-exposure would change nothing" in said(r), r.output
    assert "drop them" in said(r) and tree(out) == before
    r = runner.invoke(app, line)
    assert r.exit_code == 0, r.output
    assert (out / "journal.jsonl").is_file()


def test_a_complete_session_whose_journal_was_deleted_is_not_called_intact(
    stopped: Path, tmp_path: Path
) -> None:
    """A plain resume of a finished session whose journal.jsonl was deleted had said "complete
    … every image … matches its journaled checksum … nothing was changed", exit 0, and left it
    with no journal. It now says the journal is missing, what the images were checked against
    instead, and the rebuild as a command that pastes (run here as given); exit 2, nothing
    changed, and the same resume after the rebuild says complete."""
    out = copy_of(stopped, tmp_path)
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    (out / "journal.jsonl").unlink()
    before = tree(out)
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "journal.jsonl is missing" in text and "record is not whole" in text, text
    assert "journaled checksum" not in text and "this session is complete" not in text, text
    command = f"rti-rig run --resume {out} --rebuild-journal"
    assert command in text, text
    assert tree(out) == before
    r = runner.invoke(app, shlex.split(command)[1:])
    assert r.exit_code == 0, r.output
    assert (out / "journal.jsonl").is_file()
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert "this session is complete: all 8 steps were captured" in said(r)


def test_a_complete_session_missing_its_last_journal_line_is_told_the_rebuild(
    stopped: Path, tmp_path: Path
) -> None:
    """A completed session whose journal lost only its last line had been told "the run
    stopped after image_008's record file, before its journal line; rti-rig run --resume S
    writes it back": the run had completed, and that very resume was what refused it (a
    loop). It is told the rebuild, which mends it."""
    out = copy_of(stopped, tmp_path)
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    lines = (out / "journal.jsonl").read_text().splitlines(keepends=True)
    (out / "journal.jsonl").write_text("".join(lines[:-1]))
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "the run stopped" not in text, text
    command = f"rti-rig run --resume {out} --rebuild-journal"
    assert command in text, text
    r = runner.invoke(app, shlex.split(command)[1:])
    assert r.exit_code == 0, r.output


def test_a_session_begun_without_lights_is_said_to_have_every_light(
    tmp_path_factory: pytest.TempPathFactory,
) -> None:
    """Begun with no --lights, the refusal had said "It began with --lights 48", an option
    never given: it says what chose the 48, and that the resume continues it without it."""
    out = tmp_path_factory.mktemp("every") / "s"
    run = cut_new_session(NewSessionRequest(DOME, out), after_step=1)
    assert run.finish_reason is FinishReason.CANCELLED
    before = tree(out)
    for options in (["--lights", "12"], ["--auto-exposure"]):
        r = runner.invoke(app, ["run", str(DOME), "--resume", str(out), *options])
        assert r.exit_code == 2, r.output
        assert "It began with every light of the dome (48) (nothing" in said(r), said(r)
        assert "--lights 48" not in said(r) and "drop those options" in said(r)
    assert tree(out) == before


@pytest.fixture(scope="module")
def adaptive_stopped(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``--adaptive --lights 7`` on the shipped simulated dome, stopped after 5 images."""
    out = tmp_path_factory.mktemp("adaptive") / "s"
    assert interrupted(DOME, out, after_step=4, lights=7).finish_reason is FinishReason.CANCELLED
    return out


@pytest.mark.parametrize(
    ("options", "named", "unasked", "advised"),
    [
        # an option the session did not have: the session's own options, with it put in
        (
            ["--max-elevation-deg", "45"],
            "--max-elevation-deg 45, the session 90",
            "--adaptive not given, the session is adaptive; --lights not given, the session 7",
            ["--adaptive", "--lights", "7", "--max-elevation-deg", "45"],
        ),
        (
            ["--lights", "9"],
            "--lights 9, the session 7",
            "--adaptive not given",
            ["--adaptive", "--lights", "9"],
        ),
        # a stop put in an adaptive session keeps its --lights as the cap beside it (dropped,
        # the session of 7 had been advised one of up to 100 lights)
        (
            ["--until-error", "2"],
            "--until-error 2, the session not given",
            "--lights not given, the session 7",
            ["--until-error", "2", "--lights", "7"],
        ),
        # the session's own count without --adaptive: only what was left out differs, and the
        # request is taken as typed (a planned run of 7)
        (
            ["--lights", "7"],
            None,
            "--adaptive not given, the session is adaptive",
            ["--lights", "7"],
        ),
    ],
)
def test_a_resume_asking_another_request_advises_the_session_with_it_put_in(
    adaptive_stopped: Path,
    tmp_path: Path,
    options: list[str],
    named: str | None,
    unasked: str,
    advised: list[str] | None,
) -> None:
    """Before: the options left out were listed as the user's mistakes, first, and the new
    session repeated only the options given: ``--max-elevation-deg 45`` advised a planned run
    of every LED of the dome, not the adaptive session of 7 it had asked to band."""
    out = copy_of(adaptive_stopped, tmp_path)
    before = tree(out)
    r = runner.invoke(app, ["run", "--resume", str(out), *options])
    assert r.exit_code == 2, r.output
    text = said(r)
    differences = text.split("another session than the one in it (", 1)[1].split("). It", 1)[0]
    if named is not None:
        assert differences.startswith(
            named + "; options given with --resume are the whole request, so these differ too: "
        ), differences
    else:
        assert differences.startswith(
            "options given with --resume are the whole request, so these differ: "
        ), differences
    assert unasked in differences
    how = "with your options in place of its own" if named else "with the options you gave alone"
    new = text.split(f"to shoot it {how}, start a new session: ", 1)[1]
    words = shlex.split(new)
    assert words[:3] == ["rti-rig", "run", str(DOME)] and words[-2:] == ["--out", f"{out}-2"]
    expected = advised or ["--adaptive", *options]
    assert words[3:-2] == expected, new
    assert tree(out) == before
    if options == ["--max-elevation-deg", "45"]:  # pasted, it runs as asked
        r = runner.invoke(app, [*words[1:], "--no-verdict"])
        assert r.exit_code == 0, r.output
        header = manifest(Path(f"{out}-2"))["adaptive"]
        assert header["max_elevation_deg"] == 45 and header["design_lights"] == 7


def test_a_resume_asking_a_request_no_session_takes_says_so_rather_than_advise_it(
    adaptive_stopped: Path, tmp_path: Path
) -> None:
    """``--min-lights 6`` on an ``--adaptive --lights 7`` session: put in, the request is one
    run refuses (a minimum goes with --until-error). The refusal had advised ``rti-rig run RIG
    --min-lights 6 --out S-2``, which pasted was refused in turn; it now says why no new
    session takes it, in run's own words."""
    out = copy_of(adaptive_stopped, tmp_path)
    before = tree(out)
    r = runner.invoke(app, ["run", "--resume", str(out), "--min-lights", "6"])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "start a new session" not in text, text
    assert (
        "no new session takes it with your options in place of its own (--adaptive --lights 7 "
        "--min-lights 6): "
        "--min-lights 6 goes with --until-error" in text
    ), text
    assert (
        f"to continue it as it began, give those options or none (rti-rig run --resume {out})"
        in text
    )
    assert tree(out) == before
    # the same words as run gives the request itself
    r = runner.invoke(
        app,
        [
            "run",
            str(DOME),
            "--out",
            str(tmp_path / "n"),
            "--adaptive",
            "--lights",
            "7",
            "--min-lights",
            "6",
        ],
    )
    assert r.exit_code == 2 and "--min-lights 6 goes with --until-error" in said(r), r.output


def test_a_resume_whose_request_no_layout_takes_says_so(stopped: Path, tmp_path: Path) -> None:
    """``--lights 30 --max-elevation-deg 30`` put in a ``--lights 8`` session: the band holds
    24 LEDs, so run refuses it; the refusal had advised it all the same (a review found it)."""
    out = copy_of(stopped, tmp_path)
    r = runner.invoke(
        app, ["run", "--resume", str(out), "--lights", "30", "--max-elevation-deg", "30"]
    )
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "start a new session" not in text, text
    assert "no new session takes it with your options in place of its own (--lights 30 " in text
    assert "24 LEDs between 0° and 30°" in text, text
