"""Fault campaign: many dry-run sessions with faults at random steps, each resumed until done.

For every session it checks that no committed image was lost or changed, that the final folder is
complete and consistent, and that every recorded light is the light that really lit the image (by
re-rendering the scene for the recorded direction and for every other light the rig has: the
recorded one must explain the image best). Figures go to ``docs/reliability.md``.

    python -m benchmarks.fault_campaign [--sessions 200] [--seed 1]
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import json
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np
from rti_rig.simulator.faults import (
    FaultPlan,
    FaultyCamera,
    FaultyCarrier,
    FaultyLightSource,
    ServoFaultCarrier,
)

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.core.errors import RtiRigError
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.core.schedule import LightSchedule
from rti_rig.runtime.controller import run_session
from rti_rig.runtime.session import SessionFolder, read_manifest
from rti_rig.testing.kill_hooks import popen_session
from rti_rig.testing.verify import wrong_light_steps

REPO = Path(__file__).resolve().parent.parent
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
)
SIZE = 48


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
    """Files of every committed, verified step: these must survive unchanged."""
    out = {}
    for line in (
        (root / "journal.jsonl").read_text().splitlines()
        if (root / "journal.jsonl").exists()
        else []
    ):
        try:
            entry = json.loads(line)
        except json.JSONDecodeError:
            continue
        for name, digest in entry["sha256"].items():
            p = root / name
            if p.exists() and hashlib.sha256(p.read_bytes()).hexdigest() == digest:
                out[name] = digest
    return out


def run_in_process(cfg: Path, out: Path, n: int, fault: FaultPlan | None, resume: bool) -> None:
    """One run (new or resumed) in this process, with an optional injected device fault."""
    with build_rig(load_rig_config(cfg)) as rig:
        _run(rig, out, n, fault, resume)


def _run(rig, out: Path, n: int, fault: FaultPlan | None, resume: bool) -> None:  # type: ignore[no-untyped-def]
    from rti_rig.planner.uniform import plan_uniform

    if fault is not None:
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
    if resume:
        folder = SessionFolder.reopen(out)
        schedule = LightSchedule.from_dict(folder.manifest["schedule"])
    else:
        schedule = plan_uniform(rig.geometry, n)
        folder = SessionFolder.create(out, len(schedule))
    with contextlib.suppress(RtiRigError):  # the injected fault; the folder shows what happened
        run_session(rig, schedule, folder)


def run_killed(cfg: Path, out: Path, n: int, stage: str, k: int) -> int:
    proc = popen_session(stage, k, cfg, out, n)
    proc.communicate(timeout=300)
    return proc.returncode


def campaign(sessions: int, seed: int) -> dict:
    rng = np.random.default_rng(seed)
    faults: Counter[str] = Counter()
    stats = Counter()
    with tempfile.TemporaryDirectory() as tmp:
        tmpdir = Path(tmp)
        for i in range(sessions):
            n = int(rng.integers(6, 17))
            out = tmpdir / f"session_{i:04d}"
            fault_kind = str(rng.choice(IN_PROCESS + KILLS + SERIAL + SERVO))
            k = int(rng.integers(0, n))
            seed_i = int(rng.integers(0, 1000))
            if fault_kind in SERIAL:
                # hello is command 1; each step then sends 'light' and 'all off'.
                command = 2 + 2 * k + int(rng.integers(0, 2))
                kind_name = fault_kind.removeprefix("serial-").replace("-", "_")
                faulty = make_config(tmpdir, "emulated", seed_i, (command, kind_name))
                run_in_process(faulty, out, n, None, resume=False)
                faults[fault_kind] += 1
                first = read_manifest(out)["runner"].get("finish_reason")
                stats["serial_faults_recovered_in_session"] += int(first == "completed")
                stats["serial_faults_stopped_with_error"] += int(first == "error")
                cfg = make_config(tmpdir, "emulated", seed_i)  # the fault was a one-off
            elif fault_kind in SERVO:
                cfg = make_config(tmpdir, "servo", seed_i)
                plan = FaultPlan(fault_kind, k)
                run_in_process(cfg, out, n, plan, resume=False)
                faults.update(plan.fired)
                first = read_manifest(out)["runner"].get("finish_reason")
                stats["servo_faults_stopped_with_error"] += int(first == "error")
            else:
                cfg = make_config(tmpdir, "dome" if rng.random() < 0.6 else "arm", seed_i)
                if fault_kind in IN_PROCESS:
                    plan = FaultPlan(fault_kind, k)
                    run_in_process(cfg, out, n, plan, resume=False)
                    faults.update(plan.fired)
                else:
                    stage = fault_kind.removeprefix("sigkill-").replace("-", "_")
                    killed = run_killed(cfg, out, n, stage, k) == -9
                    faults[fault_kind] += int(killed)
                    stats["kills_that_did_not_kill"] += int(not killed)
            snapshots: dict[str, str] = {}
            resumes = 0
            while True:
                snapshots.update(committed_files(out))
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
                run_in_process(cfg, out, n, again, resume=True)
                if again is not None:  # counted only if its step was still to be captured
                    faults.update(again.fired)
            stats["sessions"] += 1
            stats["resumes"] += resumes
            m = read_manifest(out)
            complete = m["runner"].get("finish_reason") == "completed" and len(m["steps"]) == n
            lp_lines = (out / "lights.lp").read_text().splitlines()
            jpgs = sorted(p.name for p in out.glob("image_*.jpg"))
            consistent = lp_lines[0] == str(n) and [ln.split()[0] for ln in lp_lines[1:]] == jpgs
            stats["sessions_completed"] += int(complete and consistent)
            lost = sum(
                1
                for name, digest in snapshots.items()
                if not (out / name).exists()
                or hashlib.sha256((out / name).read_bytes()).hexdigest() != digest
            )
            stats["images_lost"] += lost
            stats["wrong_light_images"] += len(wrong_light_steps(cfg, out))
            stats["images_checked"] += len(m["steps"])
            if (i + 1) % 20 == 0:
                print(f"{i + 1}/{sessions} sessions", flush=True)
    return {"stats": dict(stats), "faults": dict(faults)}


def report(result: dict, sessions: int, seed: int, seconds: float) -> str:
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
        ("SIGKILL faults that failed to kill", "kills_that_did_not_kill"),
    ]
    figures = "\n".join(f"| {label} | {s.get(key, 0)} |" for label, key in labels)
    rows = "\n".join(f"| {k} | {v} |" for k, v in sorted(f.items()))
    return f"""# Reliability: fault campaign

Measured with `python -m benchmarks.fault_campaign --sessions {sessions} --seed {seed}`
({seconds:.0f} s). Each session runs a homogeneous plan of 6–16 lights on the simulated dome (60 %)
or arm (40 %), or for serial faults on the emulated dome, at {SIZE}×{SIZE} pixels, with a
fault at a random step; it is then resumed with
`--resume` semantics until complete, and 30 % of resumes get a further in-process fault.

| figure | value |
|---|---|
{figures}

## Faults injected, by kind (counted when they actually happened)

| kind | count |
|---|---|
{rows}

- `camera-failure`: the camera raises a capture error (no frame) at the step.
- `light-failure`: the dome's `light` command or the arm's move fails at the step.
- `serial-*`: a byte-level fault of the emulated dome firmware, met by the real driver over
  real pyserial on a pseudo-terminal: a reply dropped, garbled or late, a garbled command, a
  USB disconnect, a board reset before or after acknowledging.
- `sigkill-*`: the process is killed with SIGKILL (no cleanup at all) before the light, after
  the capture, half-way through writing the TIFF, between the TIFF and the JPEG, or after both
  files but before the journal line.

- `servo-*`: the emulated Dynamixel servos (real SDK, in-process port) report overload or
  overheating in their Hardware Error Status, corrupt their status packets' CRC, or fall silent,
  just as a move is commanded.
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
    args = ap.parse_args()
    out = args.out or (REPO / "docs" / "reliability.md" if args.write else None)
    t0 = time.perf_counter()
    result = campaign(args.sessions, args.seed)
    text = report(result, args.sessions, args.seed, time.perf_counter() - t0)
    print(text)
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text)
        print(f"report → {out}")


if __name__ == "__main__":
    main()
