"""Planning time from a 24-megapixel preview, weight-free path (shape from shading).

A 6000×4000 sRGB preview of the simulated relief scene is planned for a 72-LED dome (the
neuralrti dome's `.lp` from tests/data) and for the simulated arm, for each method and objective,
N = 9 and 18. BLAS is held to one thread by the planner itself; the figure is the median of
``REPEATS`` runs in one process, measured on whatever machine runs it (2 cores is the target).

Run: ``python -m benchmarks.planning_time`` (writes its section of docs/benchmarks.md).

``--cli``: the front door instead (:func:`cli_main`): the whole ``rti-rig plan --method optimal``
process on the shipped configs, start-up included (``--write``: docs/adaptive.md).
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from benchmarks.report import machine_line, write_section
from rti_rig.core import opencv_files
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.core.lp_format import read_lp
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.planner.make_plan import plan_with_report
from rti_rig.planner.topography import planning_image
from rti_rig.simulator.sim_scene import lambert_radiance, relief_scene

REPEATS = 5
LP = Path(__file__).resolve().parent.parent / "tests" / "data" / "neuralrti" / "dirs.lp"


def main() -> str:
    entries = read_lp(LP)
    dome = DomeGeometry(np.array([e.direction for e in entries]), tuple(e.name for e in entries))
    arm = ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0)
    scene = relief_scene(400, 600, seed=0)
    small = lambert_radiance(scene, direction_from_az_el(30.0, 50.0))
    srgb = np.where(small <= 0.0031308, 12.92 * small, 1.055 * small ** (1 / 2.4) - 0.055)
    preview = cv2.resize(
        (np.clip(srgb, 0, 1) * 255).astype(np.uint8), (6000, 4000), interpolation=cv2.INTER_CUBIC
    )
    assert preview.shape == (4000, 6000, 3)

    def median_s(fn) -> float:
        times = []
        for _ in range(REPEATS):
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
        return statistics.median(times)

    prep = median_s(lambda: planning_image(preview))
    rows = []
    for rig_name, geometry in (("72-LED dome", dome), ("arm", arm)):
        for n in (9, 18):
            for method, objective in (
                ("uniform", "normals"),
                ("kmeans", "normals"),
                ("optimal", "normals"),
                ("optimal", "relight"),
            ):
                med = median_s(
                    lambda g=geometry, n=n, m=method, o=objective: plan_with_report(
                        preview, g, n, m, o, preview_light=(30.0, 50.0)
                    )
                )
                rows.append((rig_name, n, method, objective, med))
                print(f"{rig_name:12s} N={n:2d} {method:8s} {objective:8s} median {med:.3f} s")
    print(f"downsample + linearise 24 MP: median {prep:.3f} s")
    lines = [
        "Command: `python -m benchmarks.planning_time`. "
        + machine_line()
        + f" os.cpu_count() = {os.cpu_count()}; median of {REPEATS} runs each.",
        "",
        "Planning from a 6000×4000 uint8 sRGB preview with the weight-free path (shape from "
        "shading, light given). Every run includes downsampling to 256 px, shape from shading, "
        "the relief-scale fit, cast-shadow maps and the objective (the `uniform` row too, "
        "because it reports the expected error).",
        "",
        f"Downsample + linearise alone: {prep:.3f} s.",
        "",
        "| rig | N | method | objective | median s |",
        "|---|---|---|---|---|",
    ]
    lines += [f"| {r} | {n} | {m} | {o} | {t:.3f} |" for r, n, m, o, t in rows]
    worst = max(t for *_, t in rows)
    lines += ["", f"Slowest case: {worst:.3f} s (target ≤ 1 s)."]
    md = "\n".join(lines)
    write_section("planning_time", md)
    return md


# --- the front door: the whole `rti-rig plan` process ------------------------------------------

#: The front-door cases: (label, rig file under the repository, lights). The shipped servo arm
#: (lights down to 0°, move-time ordering by its servos), the shipped 48-LED dome at all its
#: LEDs and half of them, and a 200-LED dome given as a bare .lp at 100 lights (no shipped dome
#: has 100 LEDs).
CLI_CASES = (
    ("shipped servo arm", "rig_configs/simulated_arm.toml", 100),
    ("shipped 48-LED dome", "rig_configs/simulated_dome.toml", 48),
    ("shipped 48-LED dome", "rig_configs/simulated_dome.toml", 24),
    ("200-LED dome (.lp)", "dome200.lp", 100),
)
REPO = Path(__file__).resolve().parent.parent


def cli_inputs(folder: Path) -> tuple[Path, Path]:
    """The preview (the relief scene lit from az 30°, el 50°, 96×128, a 16-bit PNG: linear, as
    tests/planner/test_planner_speed.py plans from) and the 200-LED dome's .lp, in ``folder``."""
    from rti_rig.core.geometry import fibonacci_cap

    scene = relief_scene(96, 128, seed=0)
    image = lambert_radiance(scene, direction_from_az_el(30.0, 50.0))
    png = folder / "preview.png"
    encoded = np.round(image / image.max() * 65535).astype(np.uint16)[..., ::-1]
    opencv_files.imwrite(png, encoded)  # a name not UTF-8 crashes OpenCV as a str
    lp = folder / "dome200.lp"
    dirs = fibonacci_cap(200, 5.0)
    lp.write_text(
        "200\n" + "".join(f"led_{i:03d}.jpg {x:.6f} {y:.6f} {z:.6f}\n" for i, (x, y, z) in
                          enumerate(dirs))
    )  # fmt: skip
    return png, lp


def default_command() -> list[str]:
    """This interpreter's ``rti-rig`` (the console script beside it, else the same entry point
    through ``-c``)."""
    exe = Path(sys.executable).with_name("rti-rig")
    if exe.is_file():
        return [str(exe)]
    return [sys.executable, "-c", "from rti_rig.cli import main; main()"]


@dataclass(frozen=True)
class CliRun:
    """One ``rti-rig plan`` process: wall and CPU seconds (user + system, the child's own), the
    report's "planned in" and the plan file's SHA-256."""

    wall_s: float
    cpu_s: float
    planned_s: float
    plan_sha256: str


def run_plan_cli(command: list[str], rig: Path, n: int, preview: Path, out: Path) -> CliRun:
    """Run ``rti-rig plan PREVIEW --rig RIG --lights N --method optimal`` once, as a user
    would (a fresh process: start-up, config, preview, plan, order, write)."""
    import hashlib
    import resource
    import subprocess

    args = [*command, "plan", str(preview), "--rig", str(rig), "--lights", str(n)]
    args += ["--method", "optimal", "--preview-light", "30,50", "--out", str(out), "--force"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(args, capture_output=True, text=True, cwd=REPO, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(args)} failed:\n{done.stdout}{done.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    sha = hashlib.sha256(out.read_bytes()).hexdigest()
    return CliRun(wall, cpu, planned_seconds(done.stdout), sha)


def planned_seconds(report: str) -> float:
    """The search's own seconds in a plan's report, as the table's "planned in" column says
    (the search, not the start-up or the arm's order); NaN if the report says none.

    Why: an arm plan's report says ``planned in 1.10 s (0.85 s choosing the lights, 0.25 s
    ordering the arm's stops)`` since d9ddd1f3, and the whole had been read, its order
    included, beside the older rows (and an ``--against`` installation's) of the search alone."""
    import re

    found = re.search(r"planned in ([0-9.]+) s(?: \(([0-9.]+) s choosing the lights)?", report)
    if found is None:
        return float("nan")
    return float(found.group(2) or found.group(1))


def cli_main(argv: list[str] | None = None) -> str:
    """Median wall and CPU seconds of the whole ``rti-rig plan --method optimal`` process per
    case of :data:`CLI_CASES`; with ``--against CMD`` (another installation's ``rti-rig``, e.g.
    an older commit's), both alternated in one run, and whether their plans are identical."""
    import argparse
    import shlex
    import tempfile

    ap = argparse.ArgumentParser(description="rti-rig plan through the front door")
    ap.add_argument("--cli", action="store_true")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--against", help="another rti-rig command to alternate with")
    ap.add_argument("--label", default="this", help="name of this checkout's rows")
    ap.add_argument("--against-label", default="against", help="name of --against's rows")
    ap.add_argument("--cases", type=int, nargs="*", help="indices into CLI_CASES (default all)")
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args(argv)
    variants = {args.label: default_command()}
    if args.against:
        variants[args.against_label] = shlex.split(args.against)
    picked = [CLI_CASES[i] for i in args.cases] if args.cases else list(CLI_CASES)
    load_before = os.getloadavg()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        preview, lp = cli_inputs(folder)
        for label, rig_name, n in picked:
            rig = lp if rig_name == "dome200.lp" else REPO / rig_name
            runs: dict[str, list[CliRun]] = {v: [] for v in variants}
            for r in range(args.repeats):
                order = list(variants) if r % 2 == 0 else list(variants)[::-1]  # alternate
                for v in order:
                    out = folder / f"{v}.lp"
                    runs[v].append(run_plan_cli(variants[v], rig, n, preview, out))
            for v, rs in runs.items():
                rows.append(
                    (
                        label,
                        n,
                        v,
                        statistics.median(x.wall_s for x in rs),
                        statistics.median(x.cpu_s for x in rs),
                        statistics.median(x.planned_s for x in rs),
                        len({x.plan_sha256 for x in rs}) == 1,
                        rs[0].plan_sha256,
                    )
                )
                _, _, _, wall, cpu, planned, same, _ = rows[-1]
                print(
                    f"{label:20s} N={n:3d} {v:10s} wall {wall:.2f} s, CPU {cpu:.2f} s, planned in "
                    f"{planned:.2f} s{'' if same else ' (plans differ between repeats!)'}",
                    flush=True,
                )
    load_after = os.getloadavg()
    cmd = f"python -m benchmarks.planning_time --cli --repeats {args.repeats}"
    if args.against:
        cmd += f" --against '{args.against}' --label '{args.label}'"
        cmd += f" --against-label '{args.against_label}'"
    lines = [
        f"Command: `{cmd} --write`. "
        + machine_line()
        + f" Medians of {args.repeats} runs, each a fresh `rti-rig plan PREVIEW --rig RIG "
        "--lights N --method optimal --preview-light 30,50` process (the 96×128 16-bit "
        "preview of the relief scene); load average (1, 5, 15 min) "
        + "/".join(f"{x:.1f}" for x in load_before)
        + " at the start, "
        + "/".join(f"{x:.1f}" for x in load_after)
        + " at the end. Wall and CPU are the whole process's (start-up, config, preview, "
        "plan, the arm's move-time order, the .lp written); \"planned in\" is the plan's own "
        "report (the search, not the start-up or the order).",
        "",
    ]
    if args.against:
        lines += [
            "| rig | N | command | wall s | CPU s | planned in s (target ≤ 1) "
            "| the same plan (.lp bytes) as the other |",
            "|---|---|---|---|---|---|---|",
        ]
        by_case: dict[tuple[str, int], set[str]] = {}
        for label, n, _v, *_rest, sha in rows:
            by_case.setdefault((label, n), set()).add(sha)
        lines += [
            f"| {label} | {n} | {v} | {w:.2f} | {c:.2f} | {p:.2f} "
            f"| {'yes' if same and len(by_case[(label, n)]) == 1 else 'NO'} |"
            for label, n, v, w, c, p, same, _sha in rows
        ]
    else:
        lines += [
            "| rig | N | wall s | CPU s | planned in s (target ≤ 1) |",
            "|---|---|---|---|---|",
        ]
        lines += [
            f"| {label} | {n} | {w:.2f} | {c:.2f} | {p:.2f} |"
            for label, n, _v, w, c, p, _same, _sha in rows
        ]
    md = "\n".join(lines)
    print(md)
    if args.write:
        from benchmarks.adaptive import DOC

        write_section("plan_cli_time", md, DOC)
    return md


if __name__ == "__main__":
    if "--cli" in sys.argv[1:]:
        cli_main(sys.argv[1:])
    else:
        from benchmarks.report import exit_on_help

        exit_on_help(f"{__doc__}\n--cli: time rti-rig plan as a whole process (--cli --help)")
        main()
