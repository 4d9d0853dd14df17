"""Whether the QA names a camera turned part-way through a session, and never a still one.

The QA claims a turn about the view axis (rti_rig/reconstruct/qa_turn.py) where the images from
one on are turned against those before by at least TURN_MIN_DEG. This shoots the shipped
simulated dome and virtual arm over every scene through ``rti-rig run`` (each session once), and
fits each as shot and with its images from two thirds of the way on turned by 0.5°, 1° and 3°
(counter-clockwise) about the frame's centre (``rti_rig.reconstruct.synthetic.
turned_session_copy``: the linear TIFFs the QA reads), through ``rti-rig fit``. It prints, per
session and turn, the turn the QA named (its first image and angle) or "-".

Run: ``python -m benchmarks.qa_turn [--lights N] [--write]`` (``--write`` replaces the section
``qa_turn`` of docs/reconstruction.md).
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

from benchmarks.front_door import ROOT, every_scene, rti_rig, sessions_args, shipped_with_scene

DOC = ROOT / "docs" / "reconstruction.md"
RIGS = ("simulated_dome.toml", "virtual_arm.toml")
TURNS = (0.0, 0.5, 1.0, 3.0)


def named_turn(session: Path, fitted: Path) -> str:
    """The turn the QA of ``session`` named: "first angle°", "-" for none, or why no QA."""
    fit = rti_rig("fit", str(session), "--out", str(fitted), "--no-ptm", "--no-hsh", "--no-normals")
    if fit.returncode != 0 or not (fitted / "qa.json").exists():
        return f"fit failed: exit {fit.returncode}"
    qa = json.loads((fitted / "qa.json").read_text(encoding="utf-8"))
    turn = qa.get("turn")
    if turn is None:
        # a turn that also shifted the crop the step check reads is said as that move
        moved = any(
            p.startswith(("object or camera moved", "may have moved"))
            for c in qa["images"]
            for p in c["problems"]
        )
        return "a shift named" if moved else "-"
    return f"{turn['first']} {turn['angle_deg']:+.2f}°"


def row(scratch: Path, rig: str, scene: str, lights: int) -> str:
    """One table row: the session as shot and turned by each of :data:`TURNS`."""
    from rti_rig.reconstruct.synthetic import turned_session_copy

    tag = f"{Path(rig).stem}_{scene}"
    config = scratch / f"{tag}.toml"
    config.write_text(shipped_with_scene(rig, scene), encoding="utf-8")
    session = scratch / tag
    ran = rti_rig(
        "run", str(config), "--out", str(session), "--lights", str(lights), "--no-verdict"
    )
    if ran.returncode != 0:
        return f"| {rig} | {scene} | run failed: exit {ran.returncode} |" + " |" * len(TURNS)
    first = lights * 2 // 3 + 1
    cells = []
    for angle in TURNS:
        shot = session
        if angle:
            shot = turned_session_copy(session, scratch / f"{tag}_{angle:g}", first, angle)
        cells.append(named_turn(shot, scratch / f"{tag}_{angle:g}_fit"))
    return f"| {rig} | {scene} | image_{first:03d} | " + " | ".join(cells) + " |"


def main(argv: list[str] | None = None) -> str:
    args = sessions_args(__doc__, argv, 24)
    from benchmarks.report import machine_line, write_section
    from rti_rig.reconstruct.qa_turn import TURN_MIN_DEG

    scenes = every_scene()
    rows = []
    with tempfile.TemporaryDirectory(prefix="qa_turn_") as tmp:
        for rig in RIGS:
            for scene in scenes:
                rows.append(row(Path(tmp), rig, scene, args.lights))
                print(rows[-1], flush=True)
    heads = " | ".join("as shot" if a == 0 else f"turned {a:g}°" for a in TURNS)
    md = "\n".join(
        [
            "## A camera turned part-way through (`python -m benchmarks.qa_turn`)",
            "",
            machine_line(),
            "",
            f"Each row a session of {args.lights} lights through `rti-rig run`, fitted by "
            "`rti-rig fit` as shot and with its images from *first turned* on turned "
            "counter-clockwise about the frame's centre. A cell is the turn the QA named "
            "(`turn` in qa.json: its first image and angle), *a shift named* where the QA "
            "named the move as a shift instead (its step check on the middle of the frame), "
            f"or - for none. The QA claims "
            f"turns of {TURN_MIN_DEG:g}° or more.",
            "",
            f"| rig | scene | first turned | {heads} |",
            "|---|---|---|" + "---|" * len(TURNS),
            *rows,
        ]
    )
    print(md)
    write_section("qa_turn", md, DOC)
    return md


if __name__ == "__main__":
    main()
