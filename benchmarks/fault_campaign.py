"""Fault campaign: many dry-run sessions with faults at random steps, each resumed until done.

For every session it checks that no committed image was lost or changed, that the final folder is
complete and consistent, and that every recorded light is the light that really lit the image (by
re-rendering the scene for the recorded direction and for every other light the rig has: the
recorded one must explain the image best). Sessions are opened and resumed through the session
use cases (``rti_rig.app.usecases.session``), as the command line does.

Besides device faults and SIGKILLs it plays what a user or a disk does to a session: a resume
on a changed rig (which must be refused, then the session's own rig finishes it), a journal cut
short followed by a chain of resumes each killed in turn, a disk that fills up (or turns
read-only, or fails) at every write point, and junk lines in the journal. Any exception that is
not a named error counts as a traceback.

    python -m benchmarks.fault_campaign [--sessions 200] [--seed 1] [--write | --out FILE]

The report is printed; it is written to ``docs/reliability.md`` only with ``--write``.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import re
import tempfile
import time
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from rti_rig.app.usecases.session import (
    NewSessionRequest,
    OpenedSession,
    ResumeRequest,
    RigChangedError,
    open_new_session,
    open_resumed_session,
    run_opened_session,
)
from rti_rig.core.errors import RtiRigError
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.runtime.session import read_manifest, scan_journal
from rti_rig.simulator.faults import (
    FaultPlan,
    FaultyCamera,
    FaultyCarrier,
    FaultyLightSource,
    ServoFaultCarrier,
)
from rti_rig.testing.disk_faults import ERRNOS, WRITE_POINTS, failing_writes
from rti_rig.testing.kill_hooks import popen_session
from rti_rig.testing.verify import wrong_light_steps

REPO = Path(__file__).resolve().parent.parent
#: The report's section of docs/reliability.md, between markers of this name.
SECTION = "fault_campaign"
IN_PROCESS = ("camera-failure", "light-failure")
SERVO = ("servo-overload", "servo-overheating", "servo-corrupt-crc", "servo-silence")
SERIAL = (
    "serial-drop-reply",
    "serial-garble-reply",
    "serial-garble-command",
    "serial-delay-reply",
    "serial-disconnect",
    "serial-reset",
    "serial-reset-after-reply",
)
KILLS = (
    "sigkill-before-light",
    "sigkill-during-capture",
    "sigkill-during-write",
    "sigkill-between-files",
    "sigkill-before-journal",
    "sigkill-after-record",
    "sigkill-after-journal",
)
#: What a user or a disk does to a session (issue #30).
SESSION = (
    "rig-changed-at-resume",
    "torn-journal-killed-resumes",
    "junk-journal-line",
    *(f"disk-full-{point}" for point in WRITE_POINTS),
)
JUNK_LINES = ("42", "[]", "null", '"text"', "{}", '{"index": 1}', "not json", '{"index": 0, ')
SIZE = 48
#: Runs again into a folder its runs left without a manifest before the session is given up and
#: counted as not finished: a fault present at every connect (a rig that never answers) had
#: the campaign run the same command again for ever.
MAX_RUNS_FROM_NOTHING = 10


def make_config(folder: Path, kind: str, seed: int, fault: tuple[int, str] | None = None) -> Path:
    """A small copy of a shipped config; ``kind`` dome, arm or emulated (with a serial fault)."""
    name = {
        "dome": "simulated_dome",
        "arm": "virtual_arm",
        "emulated": "emulated_dome",
        "servo": "simulated_arm",
    }[kind]
    src = REPO / "rig_configs" / f"{name}.toml"
    text = src.read_text()
    for big in ("512", "256"):
        text = text.replace(f"width = {big}", f"width = {SIZE}")
        text = text.replace(f"height = {big}", f"height = {SIZE}")
    text = text.replace("seed = 0", f"seed = {seed}")
    text = text.replace('transport = "pty"', 'transport = "inprocess"')
    text = text.replace('lp_file = "', f'lp_file = "{src.parent}/')
    if fault is not None:
        at, fault_kind = fault
        text += (
            f'\n[emulator]\nfaults = [{{ at_command = {at}, kind = "{fault_kind}", '
            "delay_s = 0.8 }]\n"
        )
    path = folder / f"{kind}.toml"
    path.write_text(text)
    return path


def committed_files(root: Path) -> dict[str, str]:
    """Files of every committed, verified step: these must survive unchanged.

    The journal is read as resume reads it (well-formed records only: a torn or junk line
    commits nothing)."""
    out = {}
    for entry in scan_journal(root).records:
        for name, digest in entry["sha256"].items():
            p = root / name
            if p.exists() and hashlib.sha256(p.read_bytes()).hexdigest() == digest:
                out[name] = digest
    return out


def note_committed(root: Path, seen: dict[int, set[str]]) -> None:
    """Add to ``seen`` (step → its records) each record the journal of session ``root`` holds
    now (well-formed ones, as resume reads them), as its canonical JSON: a later capture of a
    step has another record (its rig time at least), even where the simulated image has the
    same bytes."""
    import json

    if not (root / "journal.jsonl").exists():
        return
    for entry in scan_journal(root).records:
        seen.setdefault(entry["index"], set()).add(json.dumps(entry, sort_keys=True))


def reshoots(root: Path, seen: dict[int, set[str]]) -> tuple[int, int]:
    """What session ``root``'s runs set aside and shot again, at its end: (images set aside,
    committed images shot again).

    An image set aside is one step's files moved to ``recovered/`` by one resume (each resume
    has its own ``recovered/STAMP/``). A committed image shot again is a step with more than one
    record among those committed (:func:`note_committed`, whenever it was called) and the final
    journal's: its committed capture was replaced by a later one. Why: "images lost" compares
    the final files with those committed, and on the simulated rigs a step shot again has the
    same bytes, so an image set aside and shot again went unseen. (Whether a set-aside file was
    committed cannot be told by its bytes, for the same reason.)"""
    import json

    recovered = root / "recovered"
    set_aside = {
        (path.relative_to(recovered).parts[0], "_".join(path.stem.split("_")[:2]))
        for path in (recovered.rglob("image_*") if recovered.is_dir() else ())
        if path.is_file()
    }
    final = {e["index"]: json.dumps(e, sort_keys=True) for e in scan_journal(root).records}
    again = sum(1 for i, records in seen.items() if len(records | {final.get(i, "")} - {""}) > 1)
    return len(set_aside), again


def first_finish_reason(out: Path) -> str | None:
    """How the first run ended; ``"error"`` if it stopped before writing anything (a rig that
    fails at connect leaves nothing on disk)."""
    if not (out / "manifest.json").exists():
        return "error"
    return read_manifest(out)["runner"].get("finish_reason")


class Tracebacks:
    """Exceptions that were not named errors (each one a traceback a user would have seen)."""

    def __init__(self) -> None:
        self.seen: list[str] = []

    @contextlib.contextmanager
    def watch(self) -> Iterator[None]:
        try:
            yield
        except RtiRigError:
            pass  # a named error: the injected fault, met as it should be
        except Exception as exc:
            self.seen.append(f"{type(exc).__name__}: {exc}")


def _inject(opened: OpenedSession, fault: FaultPlan | None) -> None:
    rig = opened.rig
    if fault is None:
        return
    if fault.kind in SERVO:
        servo_id = rig.loaded.config.arm.dynamixel.elevation.servo_id
        rig.lighting.carrier = ServoFaultCarrier(  # type: ignore[attr-defined]
            rig.lighting.carrier, rig.emulator, fault, servo_id
        )
    elif fault.kind == "camera-failure":
        rig.camera = FaultyCamera(rig.camera, fault)
    elif isinstance(rig.geometry, DomeGeometry):
        rig.lighting.source = FaultyLightSource(rig.lighting.source, fault)  # type: ignore[attr-defined]
    else:
        rig.lighting.carrier = FaultyCarrier(rig.lighting.carrier, fault)  # type: ignore[attr-defined]


def run_in_process(
    cfg: Path | None,
    out: Path,
    n: int,
    fault: FaultPlan | None,
    resume: bool,
    tracebacks: Tracebacks,
    cancel_after: int | None = None,
) -> None:
    """One run (new or resumed) in this process, through the session use cases, with an
    optional injected device fault or a cancel after ``cancel_after`` images."""
    from rti_rig.runtime.controller import CancelToken, StepCompleted

    with tracebacks.watch():
        if resume:
            opened = open_resumed_session(ResumeRequest(out, cfg))
        else:
            assert cfg is not None
            opened = open_new_session(NewSessionRequest(cfg, out, lights=n))
        _inject(opened, fault)
        cancel = CancelToken()

        def on_event(e) -> None:  # type: ignore[no-untyped-def]
            done = len(opened.folder.committed)
            if cancel_after is not None and isinstance(e, StepCompleted) and done >= cancel_after:
                cancel.cancel()

        run_opened_session(opened, cancel, on_event)


@contextlib.contextmanager
def own_servo_state(tmpdir: Path) -> Iterator[None]:
    """The emulated servos' latched errors (kept between commands) in the campaign's own
    folder, never the user's: every session's servo config has one path."""
    import os

    from rti_rig.simulator.servo_latch import STATE_DIR_ENV

    before = os.environ.get(STATE_DIR_ENV)
    os.environ[STATE_DIR_ENV] = str(tmpdir / "servo-state")
    try:
        yield
    finally:
        if before is None:
            os.environ.pop(STATE_DIR_ENV, None)
        else:
            os.environ[STATE_DIR_ENV] = before


def recover_servos(cfg: Path, tracebacks: Tracebacks) -> None:
    """``rti-rig check CFG --reboot-faulted``, as a servo fault's error advises: an overload
    or overheating stays latched until a Reboot, and every resume would meet it at connect."""
    from rti_rig.app.usecases.check import reboot_faulted

    with tracebacks.watch():
        reboot_faulted(cfg)


def run_killed_resume(out: Path, at_light: int, *flags: str) -> tuple[int, bytes]:
    """``rti-rig run --resume OUT`` (with ``flags``) in a child process, SIGKILLed before light
    ``at_light``."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "PYTHONPATH": str(REPO)}
    argv = [sys.executable, "-m", "rti_rig.testing.kill_hooks", "before_light", str(at_light)]
    proc = subprocess.run(
        [*argv, "run", "--resume", str(out), *flags], env=env, capture_output=True, timeout=300
    )
    return proc.returncode, proc.stderr


def other_rig(tmpdir: Path, cfg: Path, kind: str, seed: int, rng: np.random.Generator) -> Path:
    """A config that differs from ``cfg`` in something the images depend on."""
    change = str(rng.choice(["kind", "size", "exposure"]))
    if change == "kind":
        return make_config(tmpdir, "arm" if kind == "dome" else "dome", seed)
    text = cfg.read_text()
    if change == "size":
        text = text.replace(f"width = {SIZE}", f"width = {SIZE // 2}")
    else:
        text = text.replace("exposure_s = 0.05", "exposure_s = 0.04")
    path = tmpdir / f"changed_{kind}.toml"
    path.write_text(text)
    return path


def session_fault(
    fault_kind: str,
    tmpdir: Path,
    out: Path,
    n: int,
    k: int,
    seed_i: int,
    rng: np.random.Generator,
    stats: Counter,
    faults: Counter,
    tracebacks: Tracebacks,
    seen: dict[int, set[str]],
) -> Path:
    """Play one of the :data:`SESSION` faults on a new session; returns its config. The
    records committed before the fault damages the journal are noted in ``seen``."""
    kind = "dome" if rng.random() < 0.6 else "arm"
    cfg = make_config(tmpdir, kind, seed_i)
    if fault_kind.startswith("disk-full-"):
        point = fault_kind.removeprefix("disk-full-")
        code_name = str(rng.choice(list(ERRNOS)))
        # the manifest is written at begin and at the end; other points once per image
        after = int(rng.integers(0, 2)) if point == "manifest" else k
        with failing_writes(point, after=after, errno_code=ERRNOS[code_name]) as fake:
            run_in_process(cfg, out, n, None, False, tracebacks)
        faults[fault_kind] += int(fake.failed > 0)
        faults[f"disk-{code_name}"] += int(fake.failed > 0)
        leftover = [*out.rglob(".*.partial"), *out.rglob(".*.tmp")] if out.exists() else []
        stats["partial_files_left"] += len(leftover)
        return cfg
    run_in_process(cfg, out, n, None, False, tracebacks, cancel_after=max(1, k))
    if not (out / "manifest.json").exists():
        return cfg
    note_committed(out, seen)
    if fault_kind == "rig-changed-at-resume":
        changed = other_rig(tmpdir, cfg, kind, seed_i, rng)
        before = sorted(p.as_posix() for p in out.rglob("*"))
        try:
            open_resumed_session(ResumeRequest(out, changed)).close()
            stats["rig_changes_accepted_silently"] += 1
        except RigChangedError:
            stats["rig_changes_refused"] += 1
        except Exception as exc:
            tracebacks.seen.append(f"{type(exc).__name__}: {exc}")
        after_files = sorted(p.as_posix() for p in out.rglob("*"))
        stats["folders_changed_by_a_refused_resume"] += int(before != after_files)
        faults[fault_kind] += 1
    elif fault_kind == "junk-journal-line":
        journal = out / "journal.jsonl"
        lines = journal.read_text().splitlines(keepends=True) if journal.exists() else []
        at = int(rng.integers(0, len(lines) + 1))
        lines.insert(at, str(rng.choice(JUNK_LINES)) + "\n")
        journal.write_text("".join(lines))
        faults[fault_kind] += 1
    elif fault_kind == "torn-journal-killed-resumes":
        journal = out / "journal.jsonl"
        for _ in range(int(rng.integers(1, 4))):  # a chain of interrupted resumes
            note_committed(out, seen)  # what the last killed resume committed, before the cut
            if journal.exists() and journal.stat().st_size:
                data = journal.read_bytes()
                journal.write_bytes(data[: -int(rng.integers(1, min(60, len(data)) + 1))])
            # a cut into a committed line (the manifest lists its step) is damage, not a kill's
            # torn append: refused without the flag, rebuilt from the manifest with it
            code, stderr = run_killed_resume(out, int(rng.integers(0, 3)), "--rebuild-journal")
            faults["torn-journal-cut"] += 1
            faults["resume-killed"] += int(code == -9)
            if b"Traceback" in stderr:
                tracebacks.seen.append(stderr.decode(errors="replace").strip().splitlines()[-1])
        faults[fault_kind] += 1
    return cfg


def run_killed(cfg: Path, out: Path, n: int, stage: str, k: int) -> int:
    proc = popen_session(stage, k, cfg, out, n)
    proc.communicate(timeout=300)
    return proc.returncode


GROUPS = {
    "device": IN_PROCESS,
    "kill": KILLS,
    "serial": SERIAL,
    "servo": SERVO,
    "session": SESSION,
}


def campaign(sessions: int, seed: int, groups: tuple[str, ...] = tuple(GROUPS)) -> dict:
    rng = np.random.default_rng(seed)
    kinds = tuple(k for g in groups for k in GROUPS[g])
    faults: Counter[str] = Counter()
    stats: Counter[str] = Counter()
    reshot: dict[str, Counter[str]] = {}  # per fault kind: what was set aside and shot again
    tracebacks = Tracebacks()
    with tempfile.TemporaryDirectory() as tmp, own_servo_state(Path(tmp)):
        tmpdir = Path(tmp)
        for i in range(sessions):
            n = int(rng.integers(6, 17))
            out = tmpdir / f"session_{i:04d}"
            fault_kind = str(rng.choice(kinds))
            seen: dict[int, set[str]] = {}  # step → its journal records, as committed
            k = int(rng.integers(0, n))
            seed_i = int(rng.integers(0, 1000))
            if fault_kind in SERIAL:
                # hello is command 1; each step then sends 'light' and 'all off'.
                command = 2 + 2 * k + int(rng.integers(0, 2))
                kind_name = fault_kind.removeprefix("serial-").replace("-", "_")
                faulty = make_config(tmpdir, "emulated", seed_i, (command, kind_name))
                run_in_process(faulty, out, n, None, False, tracebacks)
                faults[fault_kind] += 1
                first = first_finish_reason(out)
                stats["serial_faults_recovered_in_session"] += int(first == "completed")
                stats["serial_faults_stopped_with_error"] += int(first == "error")
                cfg = make_config(tmpdir, "emulated", seed_i)  # the fault was a one-off
                # the fault was in the firmware, not the config: the same rig, told so
                faulty.write_text(cfg.read_text())
            elif fault_kind in SERVO:
                cfg = make_config(tmpdir, "servo", seed_i)
                plan = FaultPlan(fault_kind, k)
                run_in_process(cfg, out, n, plan, False, tracebacks)
                faults.update(plan.fired)
                first = first_finish_reason(out)
                stats["servo_faults_stopped_with_error"] += int(first == "error")
                # the servo keeps an overload's error while powered, as a real one (the
                # emulated chain outlives the command): recovered as its error advises
                recover_servos(cfg, tracebacks)
            elif fault_kind in SESSION:
                cfg = session_fault(
                    fault_kind, tmpdir, out, n, k, seed_i, rng, stats, faults, tracebacks, seen
                )
            else:
                cfg = make_config(tmpdir, "dome" if rng.random() < 0.6 else "arm", seed_i)
                if fault_kind in IN_PROCESS:
                    plan = FaultPlan(fault_kind, k)
                    run_in_process(cfg, out, n, plan, False, tracebacks)
                    faults.update(plan.fired)
                else:
                    stage = fault_kind.removeprefix("sigkill-").replace("-", "_")
                    killed = run_killed(cfg, out, n, stage, k) == -9
                    faults[fault_kind] += int(killed)
                    stats["kills_that_did_not_kill"] += int(not killed)
            snapshots: dict[str, str] = {}
            resumes = 0
            from_nothing = 0
            while True:
                if not (out / "manifest.json").exists():
                    # stopped before anything was written: the folder (if any) holds no
                    # image, and the same command is simply run again, a bounded number of
                    # times (a fault at every connect would have it run for ever)
                    if from_nothing >= MAX_RUNS_FROM_NOTHING:
                        break
                    from_nothing += 1
                    stats["sessions_restarted_from_nothing"] += 1
                    run_in_process(cfg, out, n, None, False, tracebacks)
                    continue
                snapshots.update(committed_files(out))
                note_committed(out, seen)
                m = read_manifest(out)
                if m["runner"].get("finish_reason") == "completed":
                    break
                if resumes >= 10:
                    stats["sessions_abandoned"] += 1
                    break
                resumes += 1
                again = None
                if rng.random() < 0.3:
                    again = FaultPlan(str(rng.choice(IN_PROCESS)), int(rng.integers(0, n)))
                run_in_process(None, out, n, again, True, tracebacks)
                if again is not None:  # counted only if its step was still to be captured
                    faults.update(again.fired)
            stats["sessions"] += 1
            stats["resumes"] += resumes
            if not (out / "manifest.json").exists():
                # never begun: not finished, with no image to check
                stats["sessions_never_begun"] += 1
                stats["sessions_not_finished"] += 1
                if (i + 1) % 20 == 0:
                    print(f"{i + 1}/{sessions} sessions", flush=True)
                continue
            m = read_manifest(out)
            complete = m["runner"].get("finish_reason") == "completed" and len(m["steps"]) == n
            lp_lines = (out / "lights.lp").read_text().splitlines()
            jpgs = sorted(p.name for p in out.glob("image_*.jpg"))
            consistent = lp_lines[0] == str(n) and [ln.split()[0] for ln in lp_lines[1:]] == jpgs
            stats["sessions_completed"] += int(complete and consistent)
            stats["sessions_not_finished"] += int(not (complete and consistent))
            lost = sum(
                1
                for name, digest in snapshots.items()
                if not (out / name).exists()
                or hashlib.sha256((out / name).read_bytes()).hexdigest() != digest
            )
            stats["images_lost"] += lost
            aside, again = reshoots(out, seen)
            stats["images_set_aside"] += aside
            stats["committed_images_shot_again"] += again
            row = reshot.setdefault(fault_kind, Counter())
            row.update(sessions=1, set_aside=aside, shot_again=again)
            stats["wrong_light_images"] += len(wrong_light_steps(cfg, out))
            stats["images_checked"] += len(m["steps"])
            if (i + 1) % 20 == 0:
                print(f"{i + 1}/{sessions} sessions", flush=True)
    stats["tracebacks"] = len(tracebacks.seen)
    for line in tracebacks.seen[:10]:
        print(f"traceback: {line}", flush=True)
    return {
        "stats": dict(stats),
        "faults": dict(faults),
        "reshoots": {k: dict(v) for k, v in sorted(reshot.items())},
    }


def report(
    result: dict, sessions: int, seed: int, seconds: float, groups: tuple[str, ...] = tuple(GROUPS)
) -> str:
    s, f = result["stats"], result["faults"]
    labels = [
        ("sessions run", "sessions"),
        (
            "sessions completed after resume (all steps, `.lp` matches the images)",
            "sessions_completed",
        ),
        ("resumes needed", "resumes"),
        ("images checked", "images_checked"),
        (
            "**images lost** (committed before a fault, missing or changed at the end)",
            "images_lost",
        ),
        (
            "**wrong-light images recorded** (image better explained by another light)",
            "wrong_light_images",
        ),
        (
            "serial faults recovered inside the session (retry, reconnect)",
            "serial_faults_recovered_in_session",
        ),
        (
            "serial faults that stopped the session with an error (then resumed)",
            "serial_faults_stopped_with_error",
        ),
        (
            "servo faults that stopped the session with a named error (then resumed)",
            "servo_faults_stopped_with_error",
        ),
        ("sessions abandoned after 10 resumes", "sessions_abandoned"),
        (
            f"sessions given up after {MAX_RUNS_FROM_NOTHING} runs again that wrote nothing "
            "(a fault at every connect; counted as not finished)",
            "sessions_never_begun",
        ),
        ("**sessions that could not be finished**", "sessions_not_finished"),
        ("**tracebacks** (an exception that was not a named error)", "tracebacks"),
        ("resumes on a changed rig refused (folder untouched)", "rig_changes_refused"),
        (
            "resumes on a changed rig accepted without --accept-rig-change",
            "rig_changes_accepted_silently",
        ),
        ("folders changed by a refused resume", "folders_changed_by_a_refused_resume"),
        ("partial or temporary files left after a failed write", "partial_files_left"),
        (
            "sessions stopped before their first write, run again into the same folder",
            "sessions_restarted_from_nothing",
        ),
        ("SIGKILL faults that failed to kill", "kills_that_did_not_kill"),
        (
            "images set aside in `recovered/` (one step's files moved by one resume, kept)",
            "images_set_aside",
        ),
        (
            "committed images shot again (the step's final record is a later capture)",
            "committed_images_shot_again",
        ),
    ]
    figures = "\n".join(f"| {label} | {s.get(key, 0)} |" for label, key in labels)
    rows = "\n".join(f"| {k} | {v} |" for k, v in sorted(f.items()))
    reshot = "\n".join(
        f"| {k} | {r.get('sessions', 0)} | {r.get('set_aside', 0)} | {r.get('shot_again', 0)} |"
        for k, r in sorted(result.get("reshoots", {}).items())
    )
    faults_opt = "" if set(groups) == set(GROUPS) else f" --faults {','.join(groups)}"
    command = (
        f"python -m benchmarks.fault_campaign --sessions {sessions} --seed {seed}{faults_opt} "
        "--write"
    )
    return f"""# Reliability: fault campaign

Measured with `{command}`
({seconds:.0f} s; without `--write` the report is only printed). Each session runs a
homogeneous plan of 6–16 lights on the simulated dome (60 %) or arm (40 %), or for serial faults
on the emulated dome, at {SIZE}×{SIZE} pixels, with a fault at a random step; it is then resumed
through the same use cases as `rti-rig run --resume` until complete, and 30 % of resumes get a
further in-process fault.

| figure | value |
|---|---|
{figures}

## Faults injected, by kind (counted when they actually happened)

| kind | count |
|---|---|
{rows}

## Images set aside and shot again, by the session's first fault

"Images lost" compares each session's final files with the images committed before its
faults; a step set aside and shot again is not lost (its files are kept in `recovered/`, and on
the simulated rigs the new capture has the same bytes), so it is counted here.

| first fault | sessions | images set aside | committed images shot again |
|---|---|---|---|
{reshot}

- `camera-failure`: the camera raises a capture error (no frame) at the step.
- `light-failure`: the dome's `light` command or the arm's move fails at the step.
- `serial-*`: a byte-level fault of the emulated dome firmware, met by the real driver over
  real pyserial on a pseudo-terminal: a reply dropped, garbled or late, a garbled command, a
  USB disconnect, a board reset before or after acknowledging.
- `sigkill-*`: the process is killed with SIGKILL (no cleanup at all) before the light, after
  the capture, half-way through writing the TIFF, between the TIFF and the JPEG, after both
  files but before the step's record file, between the record file and the journal line, or
  right after the journal line.

- `servo-*`: the emulated Dynamixel servos (real SDK, in-process port) report overload or
  overheating in their Hardware Error Status, corrupt their status packets' CRC, or fall silent,
  just as a move is commanded (a read that meets one lost or corrupt reply is retried once).
  An overload or overheating stays latched until a Reboot, also between commands (the emulated
  servos stay powered), so the session is recovered with `rti-rig check CFG --reboot-faulted`
  before it is resumed, as the error advises.
- `rig-changed-at-resume`: the session is stopped, then resumed with another rig config (the
  other kind of rig, half the image width, or another exposure); the resume must be refused
  without touching the folder, and the session's own rig then finishes it.
- `torn-journal-killed-resumes`: the session is stopped, then 1–3 times in a row the journal's
  tail is cut by 1–60 bytes and `rti-rig run --resume --rebuild-journal` is SIGKILLed before one
  of its first lights (`torn-journal-cut`, `resume-killed` count each link of the chain).
- `junk-journal-line`: a line that is not a record (`42`, `[]`, `null`, a record without its
  checksum, half a record…) is inserted anywhere in the journal of a stopped session.
- `disk-full-*`: the n-th write to one kind of session file fails as a full disk (`ENOSPC`), a
  read-only one (`EROFS`) or a failing one (`EIO`) would (`disk-E*` count the errors):
  the TIFF, the JPEG, the journal line, `lights.lp` or the manifest (`failing_writes` in
  `rti_rig.testing.disk_faults`).
"""


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--sessions", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument(
        "--out", type=Path, default=None, help="write the report to this file (default: print only)"
    )
    ap.add_argument(
        "--write",
        action="store_true",
        help="write the report to the repository's docs/reliability.md",
    )
    ap.add_argument(
        "--faults",
        default=",".join(GROUPS),
        help=f"fault groups to draw from, comma-separated (default all: {','.join(GROUPS)})",
    )
    args = ap.parse_args()
    groups = tuple(g.strip() for g in args.faults.split(",") if g.strip())
    unknown = [g for g in groups if g not in GROUPS]
    if unknown:
        ap.error(f"unknown fault group(s) {', '.join(unknown)}; choose from {', '.join(GROUPS)}")
    out = args.out or (REPO / "docs" / "reliability.md" if args.write else None)
    t0 = time.perf_counter()
    result = campaign(args.sessions, args.seed, groups)
    text = report(result, args.sessions, args.seed, time.perf_counter() - t0, groups)
    print(text)
    if out is not None:
        write_report(text, out)
        print(f"report → {out}")


def write_report(text: str, out: Path) -> None:
    """Put the report between its markers in ``out``, leaving the rest of the file as it is.

    It had kept only the dome firmwares' section (from its marker on) and replaced everything
    before it: the "Emulators on a pty under CPU load" section between the two was deleted by
    every ``--write``. A file without the markers gets the report on top of what it holds."""
    begin, end = f"<!-- BEGIN {SECTION} -->", f"<!-- END {SECTION} -->"
    block = f"{begin}\n{text.strip()}\n{end}"
    old = out.read_text() if out.exists() else ""
    pattern = re.compile(re.escape(begin) + ".*?" + re.escape(end), re.DOTALL)
    if pattern.search(old):
        new = pattern.sub(lambda _m: block, old)
    else:
        new = block + ("\n\n" + old.lstrip() if old.strip() else "")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(new.rstrip() + "\n")


if __name__ == "__main__":
    main()
