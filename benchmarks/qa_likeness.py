"""How well sessions' images follow their recorded lights' order, against the QA's limits.

The QA says a session's lights are likely wrong as a whole ("images under neighbouring
recorded lights do not look alike") where ``neighbour_likeness`` in ``qa.json`` reaches
``LIKENESS_UNORDERED``, and that they belong to the images up to ``LIKENESS_ORDERED``
(rti_rig/reconstruct/qa_directions.py, rti_rig/reconstruct/qa.py). This runs the shipped
simulated rigs through the front door (``rti-rig run`` then ``rti-rig fit --no-ptm --no-hsh``,
each a new process), every light right, on every simulated scene and on the black calibration
sphere at several light counts; then the dome's sessions' images imported with their .lp
lines' lights shuffled (an .lp of another image order); then a new dome's sphere session
recorded under its ``fibonacci`` stand-in layout while its emulated LEDs are where
example_dome_48.lp says (lights wrong by 10° or more, in a partly kept order). It prints each
session's likeness and whether the verdict called its lights likely wrong, so the margins of
the limits are read from evidence.

Run: ``python -m benchmarks.qa_likeness [--write]`` (``--write`` replaces the section
``qa_likeness`` of docs/reconstruction.md).
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
from pathlib import Path

import numpy as np

from benchmarks.front_door import CONFIGS, ROOT, rti_rig, shipped_with_scene

DOC = ROOT / "docs" / "reconstruction.md"
SHUFFLE_SEEDS = (1, 2, 3)
#: The new dome's stand-in: the shipped emulated dome (real driver over a pty) with its LED
#: directions not yet measured, shooting the sphere while its LEDs are where the .lp says.
STAND_IN = (
    ('layout = "lp"\nlp_file = "example_dome_48.lp"', 'layout = "fibonacci"\ncount = 48'),
    ('name = "tablet"', 'name = "sphere"'),
)


def with_scene(scratch: Path, rig: str, scene: str) -> Path:
    """``rig`` with its ``[scene]`` named ``scene``, in ``scratch``."""
    path = scratch / f"{Path(rig).stem}_{scene}.toml"
    path.write_text(shipped_with_scene(rig, scene), encoding="utf-8")
    return path


def stand_in_dome(scratch: Path) -> Path:
    """The new dome shot under its stand-in layout (see :data:`STAND_IN`)."""
    text = (CONFIGS / "emulated_dome.toml").read_text(encoding="utf-8")
    for old, new in STAND_IN:
        if old not in text:
            raise SystemExit(f"emulated_dome.toml: no {old!r} to vary")
        text = text.replace(old, new)
    truth = CONFIGS / "example_dome_48.lp"
    text += f'\n[emulator]\nled_directions_file = "{truth.as_posix()}"\n'
    path = scratch / "emulated_dome_stand_in.toml"
    path.write_text(text, encoding="utf-8")
    return path


def fitted_qa(scratch: Path, source: Path, tag: str) -> dict | str:  # type: ignore[type-arg]
    """``qa.json`` of ``rti-rig fit source``, or why there is none."""
    out = scratch / f"{tag}_fit"
    fit = rti_rig("fit", str(source), "--out", str(out), "--no-ptm", "--no-hsh")
    if fit.returncode != 0 or not (out / "qa.json").exists():
        return f"fit failed: exit {fit.returncode}"
    return json.loads((out / "qa.json").read_text(encoding="utf-8"))


def row(rig: str, scene: str, lights: str, lp: str, qa: dict | str) -> str:  # type: ignore[type-arg]
    if isinstance(qa, str):
        return f"| {rig} | {scene} | {lights} | {lp} | {qa} | |"
    like = qa.get("neighbour_likeness")
    shown = "not measured" if like is None else f"{like:.2f}"
    called = "likely wrong" if qa["lights_likely_wrong"] else "no"
    return f"| {rig} | {scene} | {lights} | {lp} | {shown} | {called} |"


def shuffled(session: Path, folder: Path, seed: int) -> Path:
    """``session``'s images in ``folder`` with its lights.lp's lights shuffled among its lines
    (an imported acquisition: no journal to tell the .lp was edited); the .lp's path."""
    folder.mkdir()
    lines = (session / "lights.lp").read_text(encoding="utf-8").splitlines()
    count, rows = lines[0], [ln.split() for ln in lines[1:] if ln.strip()]
    for name, *_ in rows:
        shutil.copy2(session / name, folder / name)
    order = np.random.default_rng(seed).permutation(len(rows))
    text = [count, *(f"{rows[i][0]} {' '.join(rows[j][1:])}" for i, j in enumerate(order))]
    (folder / "dirs.lp").write_text("\n".join(text) + "\n", encoding="utf-8")
    return folder / "dirs.lp"


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--write", action="store_true", help="update the figures in docs/reconstruction.md"
    )
    ap.parse_args(argv)
    from benchmarks.report import machine_line, write_section
    from rti_rig.reconstruct.qa import LIKENESS_ORDERED, LIKENESS_UNORDERED
    from rti_rig.simulator.scenes import SCENE_NAMES

    scenes = ("relief", *(s for s in SCENE_NAMES if s != "flat"))  # flat: not measured
    runs = [("simulated_dome.toml", s, n) for n in (24, 48) for s in scenes]
    runs += [("virtual_arm.toml", s, 24) for s in scenes]
    runs += [("simulated_dome.toml", "sphere", n) for n in (12, 36)]
    runs += [("virtual_arm.toml", "sphere", n) for n in (12, 36, 48)]
    runs += [("simulated_arm.toml", "tablet", 24)]
    rows = []

    def say(line: str) -> None:
        rows.append(line)
        print(line, flush=True)

    with tempfile.TemporaryDirectory(prefix="qa_likeness_") as tmp:
        scratch = Path(tmp)
        for rig, scene, lights in runs:
            config = with_scene(scratch, rig, scene)
            session = scratch / f"{config.stem}_{lights}"
            ran = rti_rig("run", str(config), "--out", str(session), "--lights", str(lights))
            if ran.returncode != 0:
                say(f"| {rig} | {scene} | {lights} | right | run failed: exit {ran.returncode} | |")
                continue
            say(row(rig, scene, str(lights), "right", fitted_qa(scratch, session, session.name)))
            if rig == "simulated_dome.toml" and lights == 24:
                for seed in SHUFFLE_SEEDS:
                    lp = shuffled(session, scratch / f"{session.name}_shuffled{seed}", seed)
                    qa = fitted_qa(scratch, lp, lp.parent.name)
                    say(row(rig, scene, str(lights), f"shuffled (seed {seed})", qa))
        config = stand_in_dome(scratch)
        session = scratch / "stand_in"
        ran = rti_rig("run", str(config), "--out", str(session))
        if ran.returncode != 0:
            say(f"| emulated_dome.toml | sphere | 48 | stand-in | run failed: {ran.returncode} | |")
        else:
            qa = fitted_qa(scratch, session, "stand_in")
            say(row("emulated_dome.toml", "sphere", "48", "fibonacci stand-in", qa))
    md = "\n".join(
        [
            "## Images against their lights' order (`python -m benchmarks.qa_likeness`)",
            "",
            machine_line(),
            "",
            "Each row a session through `rti-rig run` and `rti-rig fit` (*right*: every light "
            "as recorded), or its images imported with the .lp's lights shuffled among its "
            "lines, or a new dome's sphere session under its fibonacci stand-in layout (its "
            "LEDs really where example_dome_48.lp says). *Likeness* is `neighbour_likeness` "
            "in qa.json: per image, the share of the other images that look more like it than "
            "its nearest recorded light's image, the median over the images (0: the lights "
            "order the images; about 0.5: they belong to other images). The QA says the "
            f"lights are likely wrong from {LIKENESS_UNORDERED:g} and that they belong to the "
            f"images up to {LIKENESS_ORDERED:g}.",
            "",
            "| rig | scene | lights | .lp | likeness | called |",
            "|---|---|---|---|---|---|",
            *rows,
        ]
    )
    print(md)
    write_section("qa_likeness", md, DOC)
    return md


if __name__ == "__main__":
    main()
