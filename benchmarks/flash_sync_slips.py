"""How reliably the camera-triggered dome's slip check catches a missed or double step.

The shipped ``rig_configs/emulated_cceh_rti.toml`` (the cceh/rti emulator fired by the simulated
camera's PC-sync contact; 60 LEDs in the firmware's order), on several simulated scenes, with
one fault injected at a chosen image: a lost flash pulse (``missed_pulse``), a bounced one
(``double_step``) or the dome's power cut and back just before it (``power_cycle``: the
firmware starts its order again from LED 0). Each session runs through the product's own
path (the rig the composition root builds, the controller, the slip guard) into a temporary
folder; then the emulator's record (which LED really lit each exposure) is compared with the
session's ``lights.lp``.

Printed per scene and fault: how many slips were caught **at the slipped image** (nothing
mislabelled), **late with the session disowned** (the images between are in ``lights.lp`` with
wrong lights, and the error says "do not use this session"), **late** (wrong lights in
``lights.lp`` and the error does not say so), **by the end-of-run proof** (the proof frame
shot after the last image showed the dome ran out early; the session disowned), or **never**,
and how many clean sessions raised a false alarm; then the wall time of one check on
512 × 512 px frames.
Run: ``python -m benchmarks.flash_sync_slips`` (``--quick``: fewer positions;
``--scenes coin,painting``: only those scenes; ``--kinds double_step``: only that fault).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.app.flash_sync import SyncFaultConfig
from rti_rig.core.lp_format import read_lp
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.controller import run_session
from rti_rig.runtime.flash_sync import LightSlipError
from rti_rig.runtime.session import SessionFolder

CONFIG = Path(__file__).resolve().parents[1] / "rig_configs" / "emulated_cceh_rti.toml"
SCENES = ("relief", "coin", "tablet", "painting")


def run_once(scene: str, fault: tuple[int, str] | None, root: Path) -> dict[str, object]:
    """One session; the slip reported (image, 1-based) and the lp entries whose light is wrong."""
    loaded = load_rig_config(CONFIG)
    cfg = loaded.config
    faults = [] if fault is None else [SyncFaultConfig(at_image=fault[0], kind=fault[1])]
    emu = cfg.emulator.model_copy(update={"sync_faults": faults})
    config = cfg.model_copy(
        update={"scene": cfg.scene.model_copy(update={"name": scene}), "emulator": emu}
    )
    loaded = loaded.model_copy(update={"config": config})
    rig = build_rig(loaded)
    schedule = plan_uniform(rig.geometry, rig.geometry.count, 0.0, None, 90.0)
    folder = SessionFolder.create(root, len(schedule))
    caught, disowned, by_proof = None, False, False
    try:
        run_session(rig, schedule, folder)
    except LightSlipError as exc:
        by_proof = str(exc).startswith("end-of-run proof")
        caught = len(schedule) + 1 if by_proof else int(str(exc).split()[1])
        disowned = "do not use this session" in str(exc)
    finally:
        rig.close_said()  # its failures said (a close returns them, never raises)
    camera = rig.camera
    truth = []  # the LED that lit most of each exposure
    for _n, t0, t1 in camera.windows:
        seconds = camera.dome.lit_during(t0, t1)
        truth.append(max(seconds, key=lambda k: seconds[k]) if seconds else None)
    wrong = 0
    if (root / "lights.lp").exists():
        entries = read_lp(root / "lights.lp")
        dirs = rig.geometry.directions
        for e in entries:
            i = int(e.name.split("_")[1].split(".")[0]) - 1
            led = truth[i]
            if led is None or not np.allclose(e.direction, dirs[led], atol=1e-6):
                wrong += 1
    return {"caught": caught, "wrong_in_lp": wrong, "disowned": disowned, "by_proof": by_proof}


def check_time_ms(side: int = 512) -> tuple[float, float]:
    """Median and max wall time of one check (ms), on ``side`` px RGB frames of the 60-LED order."""
    import time

    from rti_rig.app.config import rig_geometry
    from rti_rig.reconstruct.sequence_check import SequenceChecker
    from rti_rig.simulator.sim_scene import renderer_for

    dirs = rig_geometry(load_rig_config(CONFIG)).directions
    render = renderer_for("relief", side, side, 0)
    checker = SequenceChecker(dirs)
    times = []
    for i, d in enumerate(dirs):
        pixels = np.round(np.clip(render(d, 1.0) * 0.75, 0, 1) * 65535).astype(np.uint16)
        t0 = time.perf_counter()
        checker.check(i, pixels, 65535)
        times.append((time.perf_counter() - t0) * 1000)
    return float(np.median(times)), float(np.max(times))


def _positions_for(kind: str, positions: range) -> list[int]:
    """The images a fault of ``kind`` is injected before. A power cut before image 1 is left
    out: the firmware starts its order again from LED 0, where it already stood, so nothing
    slips, and the run had counted it as a slip "never caught" (4 of 60, none mislabelled)."""
    return [p for p in positions if not (kind == "power_cycle" and p == 1)]


def _option(argv: list[str], name: str, default: tuple[str, ...]) -> tuple[str, ...]:
    if name in argv and argv.index(name) + 1 < len(argv):
        return tuple(v for v in argv[argv.index(name) + 1].split(",") if v)
    return default


def main(argv: list[str]) -> None:
    quick = "--quick" in argv
    scenes = _option(argv, "--scenes", SCENES)
    kinds = _option(argv, "--kinds", ("missed_pulse", "double_step", "power_cycle"))
    positions = range(2, 60, 12) if quick else range(1, 60, 4)
    print(
        f"config {CONFIG.name}; scenes {list(scenes)}; fault positions (image, 1-based): "
        f"{list(positions)}"
    )
    totals = {kind: [0, 0, 0, 0, 0] for kind in kinds}
    false_alarms = 0
    with tempfile.TemporaryDirectory() as tmp:
        runs = 0
        for scene in scenes:
            runs += 1
            clean = run_once(scene, None, Path(tmp) / f"r{runs}")
            false_alarms += clean["caught"] is not None or clean["wrong_in_lp"] != 0
            line = [f"{scene:9s} clean: {'FALSE ALARM' if clean['caught'] else 'ok'}"]
            for kind in totals:
                at_slip = late = disowned = never = proof = 0
                mislabelled = 0
                for pos in _positions_for(kind, positions):
                    runs += 1
                    r = run_once(scene, (pos, kind), Path(tmp) / f"r{runs}")
                    mislabelled += int(r["wrong_in_lp"])  # type: ignore[call-overload]
                    if r["caught"] is None:
                        never += 1
                    elif r["by_proof"]:
                        proof += 1
                    elif r["caught"] == pos and r["wrong_in_lp"] == 0:
                        at_slip += 1
                    elif r["disowned"]:
                        disowned += 1
                    else:
                        late += 1
                for k, v in enumerate((at_slip, disowned, late, never, proof)):
                    totals[kind][k] += v
                line.append(
                    f"{kind}: {at_slip} at the slip, {disowned} late and the session disowned, "
                    f"{late} late, {proof} by the end-of-run proof (session disowned), {never} "
                    f"never ({mislabelled} lp entries mislabelled)"
                )
            print("; ".join(line), flush=True)
    for kind, (a, disowned, late, never, proof) in totals.items():
        n = len(scenes) * len(_positions_for(kind, positions))
        print(
            f"{kind}: caught at the slipped image {a}/{n} ({a / n:.0%}), late with the session "
            f"disowned {disowned}, late {late}, by the end-of-run proof {proof}, never {never}"
        )
    print(f"false alarms on clean sessions: {false_alarms}/{len(scenes)}")
    median, worst = check_time_ms()
    print(f"time per check on 512 x 512 px frames: median {median:.0f} ms, max {worst:.0f} ms")


if __name__ == "__main__":
    from benchmarks.report import exit_on_help

    exit_on_help(__doc__, writes=False)
    main(sys.argv[1:])
