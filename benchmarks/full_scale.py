"""What reading an imported acquisition's full scale buys: 12-bit data in 16-bit files.

Machine-vision and scientific cameras store 12-bit data in 16-bit files, unscaled (white 4095)
or shifted up (white 65520). This shoots the shipped simulated dome on three scenes through
``rti-rig run``, stores each session's linear images so (at 3× the exposure, clipped at the
12-bit top, and at half of it), and fits each copy through ``rti-rig fit`` twice: as it now
reads them (the full scale read from the images, rti_rig/reconstruct/full_scale.py) and with
``--white-level 65535`` (how every fit read them before). Per case it prints the reading, the
QA verdict's head and the fitted normals' error against the scene's true normals (median and
90th percentile, degrees).

Run: ``python -m benchmarks.full_scale [--lights N] [--write]`` (``--write`` replaces the
section ``full_scale`` of docs/reconstruction.md).
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np

from benchmarks.front_door import ROOT, rti_rig, sessions_args, shipped_with_scene

DOC = ROOT / "docs" / "reconstruction.md"
SCENES = ("relief", "painting", "coin")
#: (label, exposure gain, bit shift) of each 12-bit copy
CASES = (("3× exposure", 3.0, 0), ("3× exposure, shifted up", 3.0, 4), ("½ exposure", 0.5, 0))


def true_normals(scene: str) -> np.ndarray:
    """The shipped dome's scene (512 px, seed 0) as the simulator renders it."""
    from rti_rig.simulator.scenes import make_scene
    from rti_rig.simulator.sim_scene import relief_scene

    return (relief_scene(512, 512, 0) if scene == "relief" else make_scene(scene, 512, 512)).normals


def error_deg(fitted: Path, truth: np.ndarray) -> tuple[float, float]:
    """Median and 90th percentile angle (degrees) of the fit's normals from ``truth``."""
    n = np.load(fitted / "normals.npy").astype(np.float64)
    norm = np.linalg.norm(n, axis=-1)
    ok = np.isfinite(norm) & (norm > 0.5)
    cos = np.clip((n * truth).sum(-1)[ok] / norm[ok], -1.0, 1.0)
    e = np.degrees(np.arccos(cos))
    return float(np.median(e)), float(np.percentile(e, 90))


def cell(source: Path, out: Path, truth: np.ndarray, *extra: str) -> str:
    """ "reading; verdict head; median / p90 error" of one fit."""
    fit = rti_rig("fit", str(source), "--out", str(out), "--no-ptm", "--no-hsh", *extra)
    if fit.returncode != 0:
        return f"fit failed: exit {fit.returncode}"
    record = json.loads((out / "fit.json").read_text(encoding="utf-8"))["full_scale"]
    qa = json.loads((out / "qa.json").read_text(encoding="utf-8"))
    reading = "65535" if record is None else f"{record['level']} ({record['how']})"
    problems = sorted({p.split(":")[0] for c in qa["images"] for p in c["problems"]})
    head = "good" if qa["good"] else f"{qa['verdict'].split(':')[0]}: " + ", ".join(problems)
    median, p90 = error_deg(out, truth)
    return f"{reading}; {head}; {median:.2f}° / {p90:.2f}°"


def main(argv: list[str] | None = None) -> str:
    args = sessions_args(__doc__, argv, 48)
    from benchmarks.report import machine_line, write_section
    from rti_rig.reconstruct.synthetic import camera_bits_copy

    rows = []
    with tempfile.TemporaryDirectory(prefix="full_scale_") as tmp:
        scratch = Path(tmp)
        for scene in SCENES:
            config = scratch / f"{scene}.toml"
            config.write_text(shipped_with_scene("simulated_dome.toml", scene), encoding="utf-8")
            session = scratch / scene
            ran = rti_rig(
                "run", str(config), "--out", str(session), "--lights", str(args.lights),
                "--no-verdict",
            )  # fmt: skip
            if ran.returncode != 0:
                rows.append(f"| {scene} | run failed: exit {ran.returncode} | | |")
                continue
            truth = true_normals(scene)
            for k, (label, gain, shift) in enumerate(CASES):
                copy = camera_bits_copy(session, scratch / f"{scene}_{k}", gain, shift=shift)
                now = cell(copy, scratch / f"{scene}_{k}_now", truth)
                before = cell(copy, scratch / f"{scene}_{k}_65535", truth, "--white-level", "65535")
                rows.append(f"| {scene} | {label} | {now} | {before} |")
                print(rows[-1], flush=True)
    md = "\n".join(
        [
            "## 12-bit data in 16-bit files (`python -m benchmarks.full_scale`)",
            "",
            machine_line(),
            "",
            f"Each scene a session of the shipped simulated dome ({args.lights} lights) through "
            "`rti-rig run`, its linear images stored as a 12-bit camera stores them (values "
            "clipped at 4095, unscaled or shifted up by 4 bits) with a lights.lp, and fitted "
            "by `rti-rig fit` as it reads them now and with `--white-level 65535` (how every "
            "fit read them before). A cell: the full scale used (fit.json `full_scale`); the "
            "QA verdict's head and the kinds of problem named; the fitted normals' median / "
            "90th-percentile error against the scene's true normals.",
            "",
            "| scene | 12-bit copy | read now | read at 65535 (before) |",
            "|---|---|---|---|",
            *rows,
        ]
    )
    print(md)
    write_section("full_scale", md, DOC)
    return md


if __name__ == "__main__":
    main()
