"""How bright correct sessions' brightest images are, against the QA's under-exposure limit.

The QA names a session under-exposed throughout where its brightest image's brightest pixels
(``peak_level`` in ``qa.json``) reach less than ``UNDEREXPOSED_PEAK`` of full scale
(rti_rig/reconstruct/qa_underexposed.py). This runs the shipped simulated rigs through the
front door (``rti-rig run`` then ``rti-rig fit --no-ptm --no-hsh --no-normals``, each a new
process) on every simulated scene (the emulated arm on its own), with all their lights and
with lights up to 15° only (the dimmest band: grazing light), at the shipped exposure; and
the dome's relief at 1/10 and 1/50 of it. It prints each session's brightest and darkest
image's level and whether the verdict called it under-exposed, so the margin of the limit is
read from evidence.

Run: ``python -m benchmarks.qa_underexposed [--lights N] [--write]`` (``--write`` replaces the
section ``qa_underexposed`` of docs/reconstruction.md).
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

from benchmarks.front_door import ROOT, every_scene, rti_rig, sessions_args, shipped_with_scene

DOC = ROOT / "docs" / "reconstruction.md"
RIGS = ("simulated_dome.toml", "virtual_arm.toml")
BANDS = {"all": (), "up to 15°": ("--max-elevation-deg", "15")}
SHIPPED_EXPOSURE = "exposure_s = 0.05"


def variant(scratch: Path, rig: str, scene: str, exposure_factor: float) -> Path:
    """``rig`` with ``scene`` and its exposure times ``exposure_factor``, in ``scratch``."""
    text = shipped_with_scene(rig, scene)
    if SHIPPED_EXPOSURE not in text:
        raise SystemExit(f"{rig}: no {SHIPPED_EXPOSURE!r} to vary")
    text = text.replace(SHIPPED_EXPOSURE, f"exposure_s = {0.05 * exposure_factor:g}")
    path = scratch / f"{Path(rig).stem}_{scene}_{exposure_factor:g}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def one(scratch: Path, rig: str, scene: str, band: str, factor: float, lights: int) -> str:
    """One table row: the session's brightest and darkest image level and the QA's call."""
    config = variant(scratch, rig, scene, factor)
    tag = f"{config.stem}_{band.replace(' ', '').replace('°', '')}"
    session, fitted = scratch / tag, scratch / f"{tag}_fit"
    ran = rti_rig("run", str(config), "--out", str(session), "--lights", str(lights), *BANDS[band])
    if ran.returncode != 0:
        return f"| {rig} | {scene} | {band} | {factor:g} | run failed: exit {ran.returncode} | | |"
    fit = rti_rig("fit", str(session), "--out", str(fitted), "--no-ptm", "--no-hsh", "--no-normals")
    if fit.returncode != 0 or not (fitted / "qa.json").exists():
        return f"| {rig} | {scene} | {band} | {factor:g} | fit failed: exit {fit.returncode} | | |"
    qa = json.loads((fitted / "qa.json").read_text(encoding="utf-8"))
    peaks = [c["peak_level"] for c in qa["images"] if c.get("peak_level") is not None]
    called = "under-exposed" if "under-exposed throughout" in qa["verdict"] else "no"
    return (
        f"| {rig} | {scene} | {band} | {factor:g} | {max(peaks):.3f} | {min(peaks):.3f} | "
        f"{called} |"
    )


def main(argv: list[str] | None = None) -> str:
    args = sessions_args(__doc__, argv, 12)
    from benchmarks.report import machine_line, write_section
    from rti_rig.reconstruct.qa_underexposed import UNDEREXPOSED_PEAK

    scenes = every_scene()
    runs = [(rig, scene, band, 1.0) for rig in RIGS for scene in scenes for band in BANDS]
    # the emulated Dynamixel arm with its shipped scene (point lamps at 400 mm)
    runs += [("simulated_arm.toml", "tablet", band, 1.0) for band in BANDS]
    runs += [("simulated_dome.toml", "relief", "all", f) for f in (0.1, 0.02)]
    rows = []
    with tempfile.TemporaryDirectory(prefix="qa_underexposed_") as tmp:
        for rig, scene, band, factor in runs:
            rows.append(one(Path(tmp), rig, scene, band, factor, args.lights))
            print(rows[-1], flush=True)
    md = "\n".join(
        [
            "## Under-exposed sessions (`python -m benchmarks.qa_underexposed`)",
            "",
            machine_line(),
            "",
            f"Each row a session of {args.lights} lights through `rti-rig run` and `rti-rig "
            "fit`; *brightest* and *darkest* are the 99.9th percentile of the brightest and "
            "darkest image (reduced by area, as the QA reads it) as a share of full scale "
            f"(`peak_level` in qa.json). The QA calls a session under-exposed below "
            f"{UNDEREXPOSED_PEAK:.4g} in its brightest image. *Exposure* is the shipped "
            "exposure's factor.",
            "",
            "| rig | scene | lights | exposure | brightest | darkest | called |",
            "|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    print(md)
    write_section("qa_underexposed", md, DOC)
    return md


if __name__ == "__main__":
    main()
