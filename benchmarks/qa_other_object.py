"""Whether the QA names another object's picture in an acquisition, and never the object's own.

The QA names an image "not a picture of this object" where its edges correlate with the
session's below a share of its other images' (rti_rig/reconstruct/qa_other_object.py). This
shoots the shipped simulated dome and virtual arm over every scene through ``rti-rig run``,
makes each an imported acquisition (its JPEGs and lights.lp, as copied from a card), and fits
it through ``rti-rig fit`` as shot and with one image (two thirds of the way in) replaced by
the same image of each other scene. It prints, per session, what the verdict said of the
swapped image: "named" (not a picture of this object), another problem's first words, or
"good"; and whether the session as shot named any image so.

Run: ``python -m benchmarks.qa_other_object [--lights N] [--write]`` (``--write`` replaces the
section ``qa_other_object`` of docs/reconstruction.md).
"""

from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path

from benchmarks.front_door import ROOT, every_scene, rti_rig, sessions_args, shipped_with_scene

DOC = ROOT / "docs" / "reconstruction.md"
RIGS = ("simulated_dome.toml", "virtual_arm.toml")


def imported(session: Path, dst: Path, swap: Path | None, name: str) -> Path:
    """``session``'s JPEGs and lights.lp in ``dst`` (no session record), ``name`` taken from
    ``swap`` where given."""
    dst.mkdir()
    shutil.copy(session / "lights.lp", dst)
    for jpg in session.glob("image_*.jpg"):
        shutil.copy(jpg, dst / jpg.name)
    if swap is not None:
        shutil.copy(swap / name, dst / name)
    return dst


def said_of(folder: Path, fitted: Path, name: str) -> tuple[str, list[str]]:
    """What the QA said of ``name`` (its first problem's first words, "named" or "good"), and
    the images named not a picture of this object."""
    fit = rti_rig("fit", str(folder), "--out", str(fitted), "--no-ptm", "--no-hsh", "--no-normals")
    if fit.returncode != 0 or not (fitted / "qa.json").exists():
        return f"fit failed: exit {fit.returncode}", []
    qa = json.loads((fitted / "qa.json").read_text(encoding="utf-8"))
    other = [
        c["name"]
        for c in qa["images"]
        if any(p.startswith("not a picture of this object") for p in c["problems"])
    ]
    stem = Path(name).stem
    if stem in other:
        return "named", other
    problems = next((c["problems"] for c in qa["images"] if c["name"] == stem), [])
    return (problems[0].split(":")[0] if problems else "good"), other


def main(argv: list[str] | None = None) -> str:
    args = sessions_args(__doc__, argv, 24)
    from benchmarks.report import machine_line, write_section
    from rti_rig.reconstruct.qa_other_object import OTHER_OBJECT_SHARE

    scenes = every_scene()
    name = f"image_{args.lights * 2 // 3 + 1:03d}.jpg"
    rows = []
    with tempfile.TemporaryDirectory(prefix="qa_other_object_") as tmp:
        scratch = Path(tmp)
        for rig in RIGS:
            sessions: dict[str, Path] = {}
            for scene in scenes:
                tag = f"{Path(rig).stem}_{scene}"
                config = scratch / f"{tag}.toml"
                config.write_text(shipped_with_scene(rig, scene), encoding="utf-8")
                lights = ("--lights", str(args.lights))
                ran = rti_rig(
                    "run", str(config), "--out", str(scratch / tag), *lights, "--no-verdict"
                )
                if ran.returncode == 0:
                    sessions[scene] = scratch / tag
            for scene, session in sessions.items():
                _, named = said_of(
                    imported(session, scratch / f"{session.name}_asshot", None, name),
                    scratch / f"{session.name}_asshot_fit",
                    name,
                )
                cells = []
                for other, source in sessions.items():
                    if other == scene:
                        continue
                    folder = imported(session, scratch / f"{session.name}_{other}", source, name)
                    cells.append(f"{other}: {said_of(folder, Path(f'{folder}_fit'), name)[0]}")
                as_shot = ", ".join(named) if named else "none"
                rows.append(f"| {rig} | {scene} | {as_shot} | " + "; ".join(cells) + " |")
                print(rows[-1], flush=True)
    md = "\n".join(
        [
            "## Another object's picture in an acquisition "
            "(`python -m benchmarks.qa_other_object`)",
            "",
            machine_line(),
            "",
            f"Each row a session of {args.lights} lights through `rti-rig run`, imported (its "
            f"JPEGs and lights.lp) and fitted by `rti-rig fit`, as shot and with {name} "
            "replaced by the same image of each other scene. *As shot*: the images named not "
            "a picture of this object in the session as shot (none is right). Each swap: "
            "*named* where the verdict said so of the swapped image, else its first problem "
            "or *good*. The QA names an image whose registered edges correlate with the "
            f"session's below {OTHER_OBJECT_SHARE:g} of its other images' typical correlation.",
            "",
            "| rig | scene | as shot, named | the swapped image, by the scene it came from |",
            "|---|---|---|---|",
            *rows,
        ]
    )
    print(md)
    write_section("qa_other_object", md, DOC)
    return md


if __name__ == "__main__":
    main()
