"""Never lose an image: kill a session at every stage of a step, resume, and compare the folder
with an uninterrupted run of the same plan, file by file."""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest
from conftest import SMALL_DOME, line_within, write_config
from typer.testing import CliRunner

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.core.errors import SessionError
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.controller import CancelToken, FinishReason, Paused, StepCompleted, run_session
from rti_rig.runtime.session import SessionFolder
from rti_rig.testing.kill_hooks import popen_session

runner = CliRunner()
LIGHTS = 8


def said(result) -> str:  # type: ignore[no-untyped-def]
    """The command's output with rich's line wrapping undone."""
    return " ".join(result.output.split())


def digests(folder: Path) -> dict[str, str]:
    """SHA-256 of every image file and the .lp (what a user would compare)."""
    files = [*folder.glob("image_*.jpg"), *(folder / "linear").glob("*.tif"), folder / "lights.lp"]
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest() for p in files
    }


def steps_of(folder: Path) -> list[tuple]:
    m = json.loads((folder / "manifest.json").read_text())
    return [(s["index"], s["image"], s["led"], tuple(s["actual_direction"])) for s in m["steps"]]


@pytest.fixture
def reference(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    base = tmp_path_factory.mktemp("ref")
    cfg = write_config(base, SMALL_DOME)
    out = base / "uninterrupted"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 0, r.output
    return cfg, out


def child(stage: str, k: int, cfg: Path, out: Path) -> subprocess.Popen:
    return popen_session(stage, k, cfg, out, LIGHTS)


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.parametrize(
    ("stage", "recovered"),
    [
        ("before_light", 0),
        ("after_light", 0),
        ("during_capture", 0),
        ("during_write", 0),  # half a TIFF in a temporary file: never an image, removed
        ("between_files", 1),  # a complete TIFF without its JPEG or journal line: set aside
        ("before_journal", 2),  # both files complete but never committed: set aside
    ],
)
def test_sigkill_at_every_stage_then_resume(
    tmp_path: Path, reference: tuple[Path, Path], stage: str, recovered: int
) -> None:
    cfg, ref = reference
    out = tmp_path / "s"
    proc = child(stage, 3, cfg, out)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    assert len(list(out.glob("image_*.jpg"))) <= 3 + (stage == "before_journal")

    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert "3 of 8 images verified" in said(r)
    assert digests(out) == digests(ref)
    assert steps_of(out) == steps_of(ref)
    moved = [p for p in (out / "recovered").rglob("*") if p.is_file()] if recovered else []
    assert len(moved) == recovered
    assert not list(out.rglob(".*.partial"))
    m = json.loads((out / "manifest.json").read_text())
    assert m["runner"]["finish_reason"] == "completed"
    assert [run.get("finish_reason") for run in m["runs"]] == ["unrecorded", "completed"]


@pytest.mark.slow
@pytest.mark.e2e
def test_sigterm_is_an_emergency_stop_that_can_be_resumed(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    cfg, ref = reference
    out = tmp_path / "s"
    proc = child("stall", 3, cfg, out)
    deadline = time.monotonic() + 60
    journal = out / "journal.jsonl"
    while time.monotonic() < deadline:
        if journal.exists() and journal.read_text().count("\n") >= 3:
            break
        time.sleep(0.02)
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 143, stderr.decode()
    assert b"Emergency stop" in stderr
    m = json.loads((out / "manifest.json").read_text())
    assert m["runner"]["finish_reason"] == "emergency-stop"
    assert m["runner"]["teardown_failures"] == []
    assert len(m["steps"]) == 3
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert digests(out) == digests(ref)


@pytest.mark.e2e
def _cancelled_after_four(tmp_path: Path) -> tuple[Path, Path]:
    """A session of :data:`LIGHTS` on the small dome cancelled after its fourth image (the
    folder an interrupted capture leaves, to resume), and its rig config."""
    cfg = write_config(tmp_path, SMALL_DOME)
    rig = build_rig(load_rig_config(cfg))
    cancel = CancelToken()

    def stop_after_four(e) -> None:  # type: ignore[no-untyped-def]
        if isinstance(e, StepCompleted) and e.index == 3:
            cancel.cancel()

    out = tmp_path / "s"
    res = run_session(
        rig,
        plan_uniform(rig.geometry, LIGHTS),
        SessionFolder.create(out, LIGHTS),
        cancel=cancel,
        on_event=stop_after_four,
    )
    assert res.finish_reason is FinishReason.CANCELLED
    return out, cfg


def test_cancelled_session_resumes_and_corrupt_files_are_recaptured(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    _, ref = reference  # the same SMALL_DOME config, run without interruption
    out, _ = _cancelled_after_four(tmp_path)
    damaged = out / "image_002.jpg"
    data = bytearray(damaged.read_bytes())
    data[100] ^= 0xFF
    damaged.write_bytes(bytes(data))
    with open(out / "journal.jsonl", "a") as fh:
        fh.write('{"index": 4, "image": "image_0')  # torn by a crash: never committed

    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert "3 of 8 images verified" in said(r)
    assert digests(out) == digests(ref)
    kept = list((out / "recovered").rglob("image_002.jpg"))
    assert len(kept) == 1 and kept[0].read_bytes() == bytes(data)  # set aside, never deleted


@pytest.mark.e2e
def test_resume_refuses_what_it_cannot_do(tmp_path: Path, reference: tuple[Path, Path]) -> None:
    _, ref = reference
    r = runner.invoke(app, ["run", "--resume", str(ref)])  # complete, intact: no error
    assert r.exit_code == 0 and "this session is complete" in said(r), r.output
    r = runner.invoke(app, ["run", "--resume", str(tmp_path)])
    assert r.exit_code == 2 and "not an rti-rig session folder" in " ".join(r.output.split())
    r = runner.invoke(app, ["run", "--resume", str(ref), "--lights", "3"])
    assert r.exit_code == 2 and "--lights 3 gives 3 lights; the session has 8" in said(r)


@pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="POSIX flock")
def test_a_session_another_process_is_writing_is_not_resumed_under_it(tmp_path: Path) -> None:
    """A second `run --resume` on a session still being captured (it looked stuck; another
    terminal) had gone ahead: it moved the running session's image in flight to recovered/,
    shot a step the first process then failed on, and the manifest kept one of the two runs.
    The folder is locked by the process writing it; the resume is refused and nothing moves."""
    import shutil
    import sys

    out, _ = _cancelled_after_four(tmp_path)
    # the other process's image in flight: on disk, not journaled yet
    shutil.copy(out / "image_004.jpg", out / "image_005.jpg")
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import fcntl, os, sys, time\n"
            "fd = os.open(sys.argv[1], os.O_RDONLY)\n"
            "fcntl.flock(fd, fcntl.LOCK_EX)\n"
            "print('held', flush=True)\n"
            "time.sleep(120)\n",
            str(out),
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert line_within(holder, 120, "the lock holder's 'held'").strip() == "held"
        r = runner.invoke(app, ["run", "--resume", str(out)])
        assert r.exit_code == 2, r.output
        assert "in use by another rti-rig process" in said(r), said(r)
        assert (out / "image_005.jpg").exists() and not (out / "recovered").exists()
    finally:
        holder.kill()
        holder.wait()
    r = runner.invoke(app, ["run", "--resume", str(out)])  # the other process has ended
    assert r.exit_code == 0, r.output
    assert "4 of 8 images verified" in said(r), said(r)


@pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="POSIX flock")
def test_a_resume_that_fails_to_open_releases_the_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A resume refused after its reopen (the rig's check failed) or opened and closed without
    running had kept the folder's lock for as long as the calling process lived: every other
    process was told the session is "in use by another rti-rig process"."""
    import sys

    from rti_rig.app.usecases import session as usecase

    out, cfg = _cancelled_after_four(tmp_path)
    probe = [
        sys.executable,
        "-c",
        "import fcntl, os, sys\n"
        "fd = os.open(sys.argv[1], os.O_RDONLY)\n"
        "fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)\n",
        str(out),
    ]

    def failing_check(loaded, schedule, shot=frozenset()):  # type: ignore[no-untyped-def]
        raise SessionError("the rig's check failed")

    with monkeypatch.context() as m:
        m.setattr(usecase, "checked_rig", failing_check)
        with pytest.raises(SessionError):
            usecase.open_resumed_session(usecase.ResumeRequest(out, cfg))
    assert subprocess.run(probe, capture_output=True).returncode == 0

    opened = usecase.open_resumed_session(usecase.ResumeRequest(out, cfg))
    opened.close()  # opened, never run
    assert subprocess.run(probe, capture_output=True).returncode == 0


def test_a_new_session_does_not_begin_over_one_that_finished_while_it_opened(
    tmp_path: Path,
) -> None:
    """Two runs given the same new --out, the second's rig slower to open: the first's
    check, begin and finish all came between the second's check and its begin. The second
    then deleted the first's journal.jsonl and lights.lp and wrote its manifest over the
    first's (the lock had been released with the first's finish). It is refused at its begin,
    and the first session is as it was."""
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    late = SessionFolder.create(out, LIGHTS)  # checked while the folder did not exist
    rig = build_rig(load_rig_config(cfg))
    schedule = plan_uniform(rig.geometry, LIGHTS)
    run_session(rig, schedule, SessionFolder.create(out, LIGHTS))
    records = ("manifest.json", "journal.jsonl")
    before = (digests(out), {n: (out / n).read_bytes() for n in records})
    with pytest.raises(SessionError, match="not empty"):
        run_session(build_rig(load_rig_config(cfg)), schedule, late)
    assert (digests(out), {n: (out / n).read_bytes() for n in records}) == before


def test_free_disk_is_checked_before_anything_moves(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import shutil

    rig = build_rig(load_rig_config(write_config(tmp_path, SMALL_DOME)))
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage._replace(free=1_000_000))
    out = tmp_path / "s"
    with pytest.raises(SessionError, match="not enough free disk space for 8 image"):
        run_session(rig, plan_uniform(rig.geometry, LIGHTS), SessionFolder.create(out, LIGHTS))
    assert rig.lighting.source.history == []  # type: ignore[attr-defined]


def test_pause_holds_between_steps_with_lights_off(tmp_path: Path) -> None:
    rig = build_rig(load_rig_config(write_config(tmp_path, SMALL_DOME)))
    dome = rig.lighting.source  # type: ignore[attr-defined]
    control = CancelToken()
    seen: list[tuple[int, int | None, int]] = []
    out = tmp_path / "s"

    def on_event(e) -> None:  # type: ignore[no-untyped-def]
        if isinstance(e, StepCompleted) and e.index == 1:
            control.pause()
        elif isinstance(e, Paused):
            seen.append((e.index, dome.lit, len(list(out.glob("image_*.jpg")))))
            control.resume()

    res = run_session(
        rig,
        plan_uniform(rig.geometry, 4),
        SessionFolder.create(out, 4),
        cancel=control,
        on_event=on_event,
    )
    assert res.finish_reason is FinishReason.COMPLETED
    assert seen == [(2, None, 2)]


def test_wrong_light_oracle_catches_a_swapped_record(
    tmp_path: Path, reference: tuple[Path, Path]
) -> None:
    """The campaign's oracle must see a mislabelled image (else 'wrong lights: 0' means nothing)."""
    import shutil

    from rti_rig.testing.verify import wrong_light_steps

    cfg, ref = reference
    assert wrong_light_steps(cfg, ref) == []
    bad = tmp_path / "bad"
    shutil.copytree(ref, bad)
    m = json.loads((bad / "manifest.json").read_text())
    m["steps"][2]["actual_direction"], m["steps"][5]["actual_direction"] = (
        m["steps"][5]["actual_direction"],
        m["steps"][2]["actual_direction"],
    )
    (bad / "manifest.json").write_text(json.dumps(m))
    assert wrong_light_steps(cfg, bad) == [2, 5]


@pytest.mark.slow
@pytest.mark.e2e
def test_arm_session_killed_mid_move_resumes_identically(
    tmp_path: Path, arm_config_path: Path
) -> None:
    text = arm_config_path.read_text().replace("width = 512", "width = 40")
    cfg = write_config(tmp_path, text.replace("height = 512", "height = 40"), "arm.toml")
    ref = tmp_path / "ref"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(ref), "--lights", "11"])
    assert r.exit_code == 0, r.output
    out = tmp_path / "s"
    proc = popen_session("before_light", 6, cfg, out, 11)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert digests(out) == digests(ref)
    assert steps_of(out) == steps_of(ref)


def _listed(folder: Path) -> list[str]:
    """The image names ``lights.lp`` lists (empty if there is none)."""
    lp = folder / "lights.lp"
    if not lp.exists():
        return []
    return [line.split()[0] for line in lp.read_text().splitlines()[1:]]


@pytest.mark.parametrize("damaged", [("image_002.jpg",), tuple(f"image_00{i}.jpg" for i in "1234")])
def test_a_resume_stopped_before_its_first_image_leaves_lights_lp_listing_the_images_on_disk(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, damaged: tuple[str, ...]
) -> None:
    """The resume sets an unverified image aside in recovered/ before the rig opens; stopped
    then (here a full disk, as well a Ctrl-C or a dome that did not answer), lights.lp had
    still listed the image it had moved: relight pairs the .lp's lines with the JPEGs in order,
    so every later image got the wrong light. It lists exactly the JPEGs in the folder; with
    none left, it goes to recovered/ too."""
    import shutil

    out, _ = _cancelled_after_four(tmp_path)
    for name in damaged:
        (out / name).write_bytes(b"a copy cut short")
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage._replace(free=1_000_000))
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2, r.output
    assert "not enough free disk space" in said(r), said(r)
    on_disk = sorted(p.name for p in out.glob("image_*.jpg"))
    assert _listed(out) == on_disk
    if not on_disk:
        assert list((out / "recovered").rglob("lights.lp"))  # set aside, never deleted


def test_a_ctrl_c_while_a_resume_sets_images_aside_leaves_lights_lp_listing_the_images_on_disk(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A Ctrl-C that came while the resume moved an unverified image to recovered/ stopped it
    before lights.lp was relisted: the `.lp` listed the image just moved, and relight paired
    every later image with the wrong light. The moves and the relisting now finish first; the
    Ctrl-C is acted on after them (the run says it stopped, exit 130)."""
    import signal
    import threading

    import rti_rig.runtime.session as session_module

    out, _ = _cancelled_after_four(tmp_path)
    (out / "image_002.jpg").write_bytes(b"a copy cut short")
    real_replace = os.replace
    calls: list[str] = []

    def replace_then_ctrl_c(src, dst):  # type: ignore[no-untyped-def]
        real_replace(src, dst)
        # os.replace is patched process-wide: only the resume's own move of a file of this
        # session, in the main thread, is the moment meant (a writer thread's or another
        # test's leftover thread's atomic write had raised the Ctrl-C elsewhere)
        if threading.current_thread() is not threading.main_thread() or not str(src).startswith(
            str(out)
        ):
            return
        calls.append(str(src))
        if len(calls) == 1:
            signal.raise_signal(signal.SIGINT)

    monkeypatch.setattr(session_module.os, "replace", replace_then_ctrl_c)
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert calls, "the resume set nothing aside"
    assert r.exit_code == 130, r.output
    assert "Ctrl-C" in said(r)
    on_disk = sorted(p.name for p in out.glob("image_*.jpg"))
    assert "image_002.jpg" not in on_disk
    assert _listed(out) == on_disk


@pytest.mark.parametrize("argv", [["--help"], ["after_record"], ["after_record", "x", "run"]])
def test_kill_hooks_without_its_arguments_says_its_usage(argv: list[str]) -> None:
    """`python -m rti_rig.testing.kill_hooks --help` had ended in a ValueError traceback."""
    from rti_rig.testing.kill_hooks import main

    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert str(stop.value.code).startswith("usage: python -m rti_rig.testing.kill_hooks STAGE K")
