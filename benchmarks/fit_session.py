"""End-to-end `rti-rig fit` on a synthetic session: wall time and peak memory, whole processes.

The issue's yardstick (#29): relight-cli on one 72-image acquisition at 2.5 MP (JPEG in) fitted
HSH (27 planes) in 30.7 s within 615 MB and L2 normals in 7.3 s within 108 MB (measured by the
issue's author on this project's machine; relight-cli is not installed here, so the figures are
quoted, not re-measured). This script writes a session of the same shape — a glossy sphere on a
flat ground, rendered with the reconstruct package's synthetic shader, 16-bit linear TIFFs as
`rti-rig run` writes them (uncompressed) — plus two twins of it: the same images as sRGB JPEGs
(quality 95) with an ``.lp`` naming them, as relight was given, and as zlib-compressed TIFFs, as
sessions were written before 2026-11-24. It times `rti-rig fit` in a child process, reading its
peak resident memory (``ru_maxrss`` of the child) and its CPU time (user + system), which is
the figure to compare when the shared machine is loaded.

Run: ``python -m benchmarks.fit_session [--width 1936 --height 1296 --lights 72]``;
``--write`` puts the table into docs/benchmarks.md. ``--many-lights 100,300,1000 [--width 128]``
prints the peak memory as the lights grow (square images of ``--width``).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.report import machine_line, write_section
from rti_rig.core import opencv_files
from rti_rig.core.image_files import write_linear_tiff
from rti_rig.core.lp_format import LpEntry, write_lp
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals

NORMALS = ["--model", "ps", "--no-ptm", "--no-hsh", "--no-qa"]
HSH2 = ["--model", "hsh2", "--no-ptm", "--no-normals", "--no-qa"]
#: (label, input, arguments): input "tiff" (as sessions are written), "jpeg" (relight's
#: input), "zlib" (sessions written before 2026-11-24).
CASES = [
    ("normals only (least-squares PS)", "jpeg", NORMALS),
    ("normals only (least-squares PS)", "tiff", NORMALS),
    ("normals only (least-squares PS)", "zlib", NORMALS),
    ("HSH2 only (.rti)", "jpeg", HSH2),
    ("HSH2 only (.rti)", "tiff", HSH2),
    ("HSH2 only (.rti)", "zlib", HSH2),
    (
        "normals only (robust PS)",
        "tiff",
        ["--model", "robust-ps", "--no-ptm", "--no-hsh", "--no-qa"],
    ),
    ("everything (auto, normals, .ptm, .rti, QA)", "tiff", []),
]


def make_session(root: Path, width: int, height: int, n: int) -> Path:
    (root / "linear").mkdir(parents=True)
    lights = fibonacci_lights(n, 15.0)
    normals, _ = sphere_normals(height, width, 0.4)
    albedo = np.empty((height, width, 3))
    albedo[...] = (0.55, 0.45, 0.35)
    rng = np.random.default_rng(0)
    entries = []
    for i, d in enumerate(lights):
        img = render(normals, albedo, d[None], specular=0.3, shininess=40.0)[0] * 0.7
        img += rng.normal(0, 0.002, img.shape).astype(np.float32)
        px = np.clip(np.round(img * 65535), 0, 65535).astype(np.uint16)
        name = f"image_{i + 1:03d}"
        write_linear_tiff(root / "linear" / f"{name}.tif", px)
        entries.append(LpEntry(f"{name}.jpg", tuple(float(x) for x in d)))
    write_lp(root / "lights.lp", entries)
    return root


def make_twins(session: Path, jpeg: Path, zlib: Path) -> None:
    """The session's images as sRGB JPEGs beside a copy of its .lp (relight's input), and as
    zlib-compressed TIFFs (older sessions)."""
    import cv2
    import tifffile

    from rti_rig.core.image_files import linear_to_srgb8

    (zlib / "linear").mkdir(parents=True)
    jpeg.mkdir(parents=True)
    shutil.copy(session / "lights.lp", jpeg / "lights.lp")
    shutil.copy(session / "lights.lp", zlib / "lights.lp")
    for tif in sorted((session / "linear").glob("*.tif")):
        px = tifffile.imread(tif)
        write_linear_tiff(zlib / "linear" / tif.name, px, compression="zlib")
        srgb = linear_to_srgb8(px, 65535)
        jpg = jpeg / f"{tif.stem}.jpg"  # opencv_files: a name not UTF-8 crashes OpenCV as a str
        opencv_files.imwrite(jpg, srgb[..., ::-1], [cv2.IMWRITE_JPEG_QUALITY, 95])


def folder_mb(path: Path) -> float:
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file()) / 1e6


def time_fit(session: Path, extra: list[str]) -> tuple[float, float, float]:
    """Wall time, peak RSS (MB) and CPU seconds of one `rti-rig fit` process (measured by a
    wrapper whose only child it is, so ``ru_maxrss`` is that process's own)."""
    out = Path(tempfile.mkdtemp(prefix="fit_out_"))
    shutil.rmtree(out)
    cmd = [sys.executable, "-m", "rti_rig", "fit", str(session), "--out", str(out), *extra]
    wrapper = (
        "import resource, subprocess, sys, time\n"
        "t = time.perf_counter()\n"
        f"subprocess.run({cmd!r}, check=True, stdout=subprocess.DEVNULL)\n"
        "u = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
        "print(time.perf_counter() - t, u.ru_maxrss, u.ru_utime + u.ru_stime)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", wrapper], check=True, capture_output=True, text=True
    )
    wall, peak_kb, cpu = done.stdout.split()
    shutil.rmtree(out, ignore_errors=True)
    return float(wall), float(peak_kb) / 1024.0, float(cpu)


def memory_scaling(lights: int, write: bool) -> None:
    """Peak RSS of the full fit at two sizes, extrapolated linearly to 24 MP (6000 × 4000).

    24 MP × 100 lights is too slow to render and fit on the shared 2-core machine; the fit's
    memory is a fixed part (interpreter, libraries, the 30 000-pixel sample, the QA crop, one
    24 MB band and its temporaries) plus a per-pixel part (the PNG encoding buffers; the
    memmapped maps are dropped from memory band by band), so two sizes give the line.
    """
    sizes = [(684, 456), (1368, 912)]
    points = []
    work = Path(tempfile.mkdtemp(prefix="fit_mem_"))
    try:
        for w, h in sizes:
            session = make_session(work / f"s{w}", w, h, lights)
            wall, peak, _ = time_fit(session, [])
            points.append((w * h / 1e6, peak, wall))
            print(f"{w} x {h} x {lights}: {wall:.1f} s, peak RSS {peak:.0f} MB", flush=True)
            shutil.rmtree(session, ignore_errors=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    (m0, p0, _), (m1, p1, _) = points
    slope = (p1 - p0) / (m1 - m0)
    at24 = p0 + slope * (24.0 - m0)
    table = "\n".join(
        [
            "## `rti-rig fit` memory at 24 MP (extrapolated)",
            "",
            f"{machine_line()} Command: `python -m benchmarks.fit_session --memory-scaling "
            f"--lights {lights}`.",
            "",
            f"Full fit (auto model, normals, .ptm, .rti, QA) of {lights} RGB 16-bit TIFFs, peak "
            "RSS of the whole process at two sizes; 24 MP is extrapolated linearly "
            f"({slope:.0f} MB per megapixel) because rendering and fitting it takes too long "
            "on this shared machine. Target (issue #29): within 2 GB.",
            "",
            "| size (MP) | peak RSS (MB) | wall (s) |",
            "|---|---|---|",
            *[f"| {m:.2f} | {p:.0f} | {t:.0f} |" for m, p, t in points],
            f"| 24 (extrapolated) | {at24:.0f} | — |",
        ]
    )
    print(table)
    if write:
        print(f"written to {write_section('fit_memory', table)}")


def make_jpeg_session(root: Path, width: int, height: int, n: int) -> Path:
    """A large JPEG acquisition, cheaply: each image rendered and encoded to sRGB at a quarter
    of the size, then upscaled as 8 bits (the fit's memory depends on the size, not on the
    detail)."""
    import cv2

    from rti_rig.core.image_files import linear_to_srgb8

    root.mkdir(parents=True)
    lights = fibonacci_lights(n, 15.0)
    small = (max(1, height // 4), max(1, width // 4))
    normals, _ = sphere_normals(*small, 0.4)
    albedo = np.empty((*small, 3))
    albedo[...] = (0.55, 0.45, 0.35)
    entries = []
    for i, d in enumerate(lights):
        img = render(normals, albedo, d[None], specular=0.3, shininess=40.0)[0] * 0.7
        srgb = linear_to_srgb8(np.clip(np.round(img * 65535), 0, 65535).astype(np.uint16), 65535)
        srgb = cv2.resize(srgb, (width, height), interpolation=cv2.INTER_LINEAR)
        name = f"image_{i + 1:03d}.jpg"
        opencv_files.imwrite(root / name, srgb[..., ::-1], [cv2.IMWRITE_JPEG_QUALITY, 95])
        entries.append(LpEntry(name, tuple(float(x) for x in d)))
    write_lp(root / "lights.lp", entries)
    return root


def memory_at(width: int, height: int, lights: int, write: bool) -> None:
    """Peak RSS of `rti-rig fit --model ps` (normal maps, .ptm, .rti, QA) measured, not
    extrapolated, on a JPEG acquisition of the given size."""
    work = Path(tempfile.mkdtemp(prefix="fit_big_"))
    try:
        t0 = time.perf_counter()
        session = make_jpeg_session(work / "jpeg", width, height, lights)
        print(f"{lights} JPEGs written in {time.perf_counter() - t0:.0f} s", flush=True)
        rows = []
        for label, extra in (
            ("normals only (least-squares PS)", NORMALS),
            ("normals, .ptm, .rti (HSH2), QA", ["--model", "ps"]),
        ):
            wall, peak, cpu = time_fit(session, extra)
            rows.append((label, wall, cpu, peak))
            print(f"{label}: {wall:.0f} s, cpu {cpu:.0f} s, peak RSS {peak:.0f} MB", flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    mp = width * height / 1e6
    table = "\n".join(
        [
            f"## `rti-rig fit` memory at {mp:.0f} MP (measured)",
            "",
            f"{machine_line()} Command: `python -m benchmarks.fit_session --memory-at "
            f"{width}x{height} --lights {lights}`.",
            "",
            f"{lights} RGB JPEGs of {width} × {height} ({mp:.1f} MP; rendered at a quarter of "
            "the size and upscaled, since the memory depends on the size, not on the detail), "
            "one `python -m rti_rig fit` process per case, outputs written; peak resident set "
            "of that process (`ru_maxrss`). Target (issue #29): 24 MP × 100 lights with normal "
            "maps within 2 GB.",
            "",
            "| case | wall time (s) | CPU time (s) | peak RSS (MB) |",
            "|---|---|---|---|",
            *[f"| {label} | {w:.0f} | {c:.0f} | {p:.0f} |" for label, w, c, p in rows],
        ]
    )
    print(table)
    if write:
        print(f"written to {write_section('fit_memory', table)}")


#: (label, arguments) of the many-lights memory cases
MANY_LIGHTS_CASES = [
    ("PTM only", ["--model", "ptm", "--no-qa"]),
    ("HSH2 only", ["--model", "hsh2", "--no-qa"]),
    ("everything but the QA", ["--no-qa"]),
    ("everything (auto, normals, .ptm, .rti, QA)", []),
]


def many_lights(side: int, counts: list[int]) -> None:
    """Peak RSS of `rti-rig fit` as the lights grow, at one small image size (printed only).

    The fit's memory should be bounded by its budgets (a band's, the pixel sample's), not grow
    with lights × pixels: at 1000 RGB lights of 128 × 128 a PTM fit peaked at 1.4 GB while the
    sample was 30 000 pixels at any light count. The QA works on a crop and a coverage grid of
    every image, so its memory does grow with the lights: the last two cases differ only by
    the QA, and their difference is printed as the QA's share."""
    work = Path(tempfile.mkdtemp(prefix="fit_many_"))
    rows = []
    shares = []  # (lights, peak without the QA, peak with it)
    try:
        for n in counts:
            session = make_session(work / f"s{n}", side, side, n)
            pixel_mb = n * side * side * 3 * 2 / 1e6
            for label, extra in MANY_LIGHTS_CASES:
                wall, peak, cpu = time_fit(session, extra)
                rows.append((n, pixel_mb, label, wall, cpu, peak))
                print(f"{n} lights, {label}: {wall:.1f} s, peak RSS {peak:.0f} MB", flush=True)
            without, with_qa = (r[-1] for r in rows[-2:])
            shares.append((n, without, with_qa))
            print(f"{n} lights: the QA's share {with_qa - without:.0f} MB", flush=True)
            shutil.rmtree(session, ignore_errors=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(
        "\n".join(
            [
                f"## `rti-rig fit` memory at many lights ({side} × {side} RGB 16-bit TIFFs)",
                "",
                f"{machine_line()} Command: `python -m benchmarks.fit_session --many-lights "
                f"{','.join(str(n) for n in counts)} --width {side}`.",
                "",
                "| lights | pixels (MB, 16-bit) | case | wall (s) | CPU (s) | peak RSS (MB) |",
                "|---|---|---|---|---|---|",
                *[
                    f"| {n} | {mb:.1f} | {label} | {w:.1f} | {c:.1f} | {p:.0f} |"
                    for n, mb, label, w, c, p in rows
                ],
                "",
                "| lights | without QA (MB) | with QA (MB) | the QA's share (MB) |",
                "|---|---|---|---|",
                *[f"| {n} | {a:.0f} | {b:.0f} | {b - a:.0f} |" for n, a, b in shares],
            ]
        )
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=1936)
    parser.add_argument("--height", type=int, default=1296)
    parser.add_argument("--lights", type=int, default=72)
    parser.add_argument("--write", action="store_true")
    parser.add_argument(
        "--only", default="", help="run only the cases whose label contains this text"
    )
    parser.add_argument("--memory-scaling", action="store_true", help="see memory_scaling()")
    parser.add_argument("--memory-at", default="", help="WIDTHxHEIGHT: see memory_at()")
    parser.add_argument(
        "--many-lights",
        default="",
        help="comma-separated light counts: peak RSS as the lights grow at --width px square "
        "(see many_lights(); printed, never written)",
    )
    args = parser.parse_args()
    if args.many_lights:
        side = args.width if args.width != 1936 else 128
        many_lights(side, [int(x) for x in args.many_lights.split(",")])
        return
    if args.memory_at:
        w, h = (int(x) for x in args.memory_at.lower().split("x"))
        memory_at(w, h, args.lights if args.lights != 72 else 100, args.write)
        return
    if args.memory_scaling:
        memory_scaling(args.lights if args.lights != 72 else 100, args.write)
        return
    work = Path(tempfile.mkdtemp(prefix="fit_bench_"))
    try:
        t0 = time.perf_counter()
        sources = {"tiff": work / "session", "jpeg": work / "jpeg", "zlib": work / "zlib"}
        make_session(sources["tiff"], args.width, args.height, args.lights)
        make_twins(sources["tiff"], sources["jpeg"], sources["zlib"])
        sizes = {k: folder_mb(v) for k, v in sources.items()}
        print(f"sessions written in {time.perf_counter() - t0:.1f} s: {sizes}")
        rows = []
        for label, kind, extra in CASES:
            if args.only not in label:
                continue
            wall, peak, cpu = time_fit(sources[kind], extra)
            rows.append((label, kind, wall, cpu, peak))
            print(
                f"{label:45s} {kind:5s} {wall:7.1f} s  cpu {cpu:7.1f} s  peak RSS {peak:7.0f} MB",
                flush=True,
            )
    finally:
        shutil.rmtree(work, ignore_errors=True)
    mp = args.width * args.height / 1e6
    inputs = {
        "tiff": f"uncompressed 16-bit TIFF as sessions are written ({sizes['tiff']:.0f} MB)",
        "jpeg": f"sRGB JPEG q95 beside the .lp, relight's input ({sizes['jpeg']:.0f} MB)",
        "zlib": f"zlib 16-bit TIFF, sessions before 2026-11-24 ({sizes['zlib']:.0f} MB)",
    }
    lines = [
        "## `rti-rig fit` end to end (whole processes)",
        "",
        f"{machine_line()} Command: `python -m benchmarks.fit_session --width {args.width} "
        f"--height {args.height} --lights {args.lights}`.",
        "",
        f"{args.lights} RGB images of {args.width} × {args.height} ({mp:.1f} MP), synthetic glossy "
        "sphere, as three inputs: "
        + "; ".join(f"**{k}**: {v}" for k, v in inputs.items())
        + ". Each case is one `python -m rti_rig fit` process, outputs written. Peak memory is "
        "that process's maximum resident set (`ru_maxrss`); CPU is its user + system time "
        "(the figure to compare when other jobs share the 2 cores). relight-cli (quoted from "
        "issue #29, same shape, JPEG in): HSH 30.7 s / 615 MB, L2 normals 7.3 s / 108 MB.",
        "",
        "| case | input | wall time (s) | CPU time (s) | peak RSS (MB) |",
        "|---|---|---|---|---|",
        *[
            f"| {label} | {kind} | {wall:.1f} | {cpu:.1f} | {peak:.0f} |"
            for label, kind, wall, cpu, peak in rows
        ],
    ]
    table = "\n".join(lines)
    print(table)
    if args.write:
        print(f"written to {write_section('fit_session', table)}")


if __name__ == "__main__":
    main()
