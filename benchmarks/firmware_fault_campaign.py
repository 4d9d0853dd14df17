"""Fault campaign on the real-firmware dome profiles: a byte-level fault per session, then resume.

For each session: a built-in firmware profile (its shipped emulated config), 6 lights, and one
fault of the firmware emulator (reply lost, garbled or late; the board resetting instead of a
command; the USB port gone for 0.3 s) at a random command. The session runs through the real
scripted driver and real pyserial on a pty; if it stops, it is resumed (without the fault) until
complete. Checked: the committed images survive unchanged, the folder ends complete and
consistent, every image is explained best by its recorded LED (the wrong-light check), and the
emulator's record shows every LED off at the end of every run (``dark at end``).

    python -m benchmarks.firmware_fault_campaign [--sessions 24] [--seed 1] [--at-connect] [--write]

``--write`` puts the figures in their section of docs/reliability.md. The fault is drawn after
the connect (from command 4: the connect's commands and the first all-off come before) unless
``--at-connect``, which draws it at commands 1-3 only, the connect's handshake or init
commands and its first all-offs, where a session had failed at its start; its figures have a
section of their own.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import re
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np

from benchmarks.fault_campaign import committed_files, first_finish_reason
from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.core.errors import RtiRigError
from rti_rig.core.schedule import LightSchedule
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.controller import run_session
from rti_rig.runtime.session import SessionFolder, read_manifest
from rti_rig.testing.verify import wrong_light_steps

REPO = Path(__file__).resolve().parent.parent
CONFIGS = {
    "nab-rti-v1": "emulated_nab_rti_v1.toml",
    "rtipy": "emulated_rtipy.toml",
    "minirti": "emulated_minirti.toml",
    "elexol-24r1": "emulated_elexol.toml",
    "rti-dome-m": "emulated_rti_dome.toml",
    "nichlock": "emulated_nichlock.toml",
}
KINDS = ("drop_reply", "garble_reply", "delay_reply", "reset", "disconnect")
LIGHTS = 6
SECTION = "firmware_faults"
#: Commands the fault is drawn from: after the connect, or at it (``--at-connect``).
AFTER_CONNECT = (4, 4 + 2 * LIGHTS)
AT_CONNECT = (1, 4)
#: Runs after the first before a session is given up (counted as abandoned, not completed).
MAX_RESUMES = 5


def make_config(folder: Path, profile: str, fault: tuple[int, str] | None) -> Path:
    text = (REPO / "rig_configs" / CONFIGS[profile]).read_text()
    if fault is not None:
        at, kind = fault
        delay = 0.3 if kind == "disconnect" else 1.5
        text += (
            f'\n[emulator]\nfaults = [{{at_command = {at}, kind = "{kind}", delay_s = {delay}}}]\n'
        )
    path = folder / f"{profile}.toml"
    path.write_text(text)
    return path


def run_once(cfg: Path, out: Path, resume: bool) -> bool:
    """One run (new or resumed); True if the emulator's record ends with every LED off."""
    with build_rig(load_rig_config(cfg)) as rig:
        board = rig.emulator  # type: ignore[attr-defined]
        if resume:
            folder = SessionFolder.reopen(out)
            schedule = LightSchedule.from_dict(folder.manifest["schedule"])
        else:
            schedule = plan_uniform(rig.geometry, LIGHTS)
            folder = SessionFolder.create(out, len(schedule))
        with contextlib.suppress(RtiRigError):
            run_session(rig, schedule, folder)
        end = time.monotonic() + 5.0  # bytes on a pty reach the emulator's thread shortly after
        while board.lit and time.monotonic() < end:
            time.sleep(0.01)
        return not board.lit


def campaign(sessions: int, seed: int, at_connect: bool = False) -> dict:
    rng = np.random.default_rng(seed)
    low, high = AT_CONNECT if at_connect else AFTER_CONNECT
    stats: Counter[str] = Counter()
    per_kind: Counter[str] = Counter()
    profiles = list(CONFIGS)
    with tempfile.TemporaryDirectory() as tmp:
        tmpdir = Path(tmp)
        for i in range(sessions):
            profile = profiles[i % len(profiles)]
            kind = str(rng.choice(KINDS))
            at = int(rng.integers(low, high))  # 1-3: the connect and the first all-off
            out = tmpdir / f"s{i:03d}"
            dark = run_once(make_config(tmpdir, profile, (at, kind)), out, resume=False)
            per_kind[kind] += 1
            # a run that failed at connect wrote nothing (the folder is begun once the rig
            # answers): stopped with its error, and run again from nothing below
            first = first_finish_reason(out)
            stats["stopped_at_connect"] += int(not (out / "manifest.json").exists())
            stats["recovered_in_session"] += int(first == "completed")
            stats["stopped_with_named_error"] += int(first == "error")
            stats["runs"] += 1
            stats["dark_at_end"] += int(dark)
            snapshots: dict[str, str] = {}
            clean = make_config(tmpdir, profile, None)
            resumes = 0
            while first_finish_reason(out) != "completed":
                if resumes >= MAX_RESUMES:
                    stats["abandoned"] += 1
                    break
                resumes += 1
                stats["runs"] += 1
                if not (out / "manifest.json").exists():
                    stats["dark_at_end"] += int(run_once(clean, out, resume=False))
                    continue
                snapshots.update(committed_files(out))
                stats["dark_at_end"] += int(run_once(clean, out, resume=True))
            stats["sessions"] += 1
            if not (out / "manifest.json").exists():
                # every run failed at connect: never begun, no image to check (reading its
                # manifest stopped the campaign with a traceback)
                stats["never_begun"] += 1
                print(f"{i + 1}/{sessions} {profile} {kind}@{at}: never begun", flush=True)
                continue
            m = read_manifest(out)
            complete = m["runner"].get("finish_reason") == "completed" and len(m["steps"]) == LIGHTS
            stats["sessions_completed"] += int(complete)
            stats["images_lost"] += sum(
                1
                for name, digest in snapshots.items()
                if not (out / name).exists()
                or hashlib.sha256((out / name).read_bytes()).hexdigest() != digest
            )
            wrong = wrong_light_steps(clean, out)
            stats["wrong_light_images"] += len(wrong)
            stats["images_checked"] += len(m["steps"])
            print(
                f"{i + 1}/{sessions} {profile} {kind}@{at}: {first}; resumes {resumes}, "
                f"wrong-light steps {wrong}, dark after the first run: {dark}",
                flush=True,
            )
    return {"stats": dict(stats), "faults": dict(per_kind)}


def report(result: dict, sessions: int, seed: int, seconds: float, at_connect: bool = False) -> str:
    s, f = result["stats"], result["faults"]
    rows = [
        ("sessions (one firmware fault each)", s.get("sessions", 0)),
        ("recovered inside the session (retry, reconnect)", s.get("recovered_in_session", 0)),
        ("stopped with a named error, then resumed", s.get("stopped_with_named_error", 0)),
        (
            "of which stopped at connect, before anything was written (run again from nothing)",
            s.get("stopped_at_connect", 0),
        ),
        ("sessions completed", s.get("sessions_completed", 0)),
        (
            f"sessions abandoned after {MAX_RESUMES} runs again (not completed)",
            s.get("abandoned", 0),
        ),
        (
            "of which never begun (every run stopped at connect, nothing written)",
            s.get("never_begun", 0),
        ),
        ("images checked", s.get("images_checked", 0)),
        ("images lost or changed", s.get("images_lost", 0)),
        ("images under a wrong light", s.get("wrong_light_images", 0)),
        ("runs (first + resumes)", s.get("runs", 0)),
        ("runs whose emulator record ends with every LED off", s.get("dark_at_end", 0)),
    ]
    kinds = ", ".join(f"{k} {v}" for k, v in sorted(f.items()))
    low, high = AT_CONNECT if at_connect else AFTER_CONNECT
    return "\n".join(
        [
            "## Real-firmware dome profiles under faults" + (" at connect" if at_connect else ""),
            "",
            f"Command: `python -m benchmarks.firmware_fault_campaign --sessions {sessions} "
            f"--seed {seed}{' --at-connect' if at_connect else ''} --write` ({seconds:.0f} s). "
            "Profiles in turn: "
            + ", ".join(CONFIGS)
            + f"; {LIGHTS} lights each; the fault at a command drawn from {low} to {high - 1}; "
            f"faults: {kinds}.",
            "",
            "| | count |",
            "|---|---|",
            *[f"| {label} | {value} |" for label, value in rows],
        ]
    )


def write_section(text: str, path: Path, section: str = SECTION) -> None:
    begin, end = f"<!-- BEGIN {section} -->", f"<!-- END {section} -->"
    block = f"{begin}\n{text}\n{end}"
    old = path.read_text() if path.exists() else ""
    pattern = re.compile(re.escape(begin) + ".*?" + re.escape(end), re.DOTALL)
    new = (
        pattern.sub(lambda _m: block, old) if pattern.search(old) else old.rstrip() + "\n\n" + block
    )
    path.write_text(new.rstrip() + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--sessions", type=int, default=24)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument(
        "--at-connect",
        action="store_true",
        help="draw each fault at commands 1-3 (the connect) rather than after it",
    )
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args()
    t0 = time.perf_counter()
    result = campaign(args.sessions, args.seed, args.at_connect)
    text = report(result, args.sessions, args.seed, time.perf_counter() - t0, args.at_connect)
    print(text)
    if args.write:
        section = f"{SECTION}_at_connect" if args.at_connect else SECTION
        write_section(text, REPO / "docs" / "reliability.md", section)


if __name__ == "__main__":
    main()
