"""Fit throughput of each reconstruction model against a plain matrix product of the same shape.

Every linear model's fit is, at heart, ``(p × N) @ (N × pixels)``; this benchmark shows what the
rest (reading bands, float conversion, guards, the robust passes of photometric stereo) costs
on top, measured in the same run on the same machine. Figures: median wall time over repeats,
throughput in pixels × lights per second, the ratio to the matrix product, and the peak traced
memory of one fit compared with the float32 stack it never builds.

Run: ``OPENBLAS_NUM_THREADS=1 python -m benchmarks.fit_throughput`` (one BLAS thread: on a
shared machine, threaded BLAS on tall-skinny products loses more to contention than it gains;
defaults: 512 × 512 grey pixels, 48 lights, 5 repeats); ``--size``, ``--lights``,
``--repeats``, ``--tile-rows`` change the shape. It also writes a small accuracy table
(``--accuracy-size``, 0 to skip): angular error and held-out relighting PSNR/SSIM of each
model on a synthetic sphere with highlights.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
import tracemalloc
from collections.abc import Callable

import numpy as np

from benchmarks.metrics import angular_error_deg, relight_psnr, relight_ssim
from benchmarks.report import machine_line, write_section
from rti_rig.reconstruct import N_COEFFICIENTS, fit_model, select_model
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals

MODELS = ("ps", "ps-robust", "lambert", "hsh1", "ptm", "hsh2", "hsh3")
#: Band height for the memory measurement: small, to show the streamed peak.
PEAK_TILE_ROWS = 32


def _median_time(fn: Callable[[], object], repeats: int) -> float:
    fn()  # warm-up: first-touch page faults and BLAS thread start-up
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _paired_times(
    a: Callable[[], object], b: Callable[[], object], repeats: int
) -> tuple[float, float]:
    """Medians of ``a`` and ``b`` timed alternately (a, b, a, b, …) after a warm-up of each:
    on a shared machine both see the same load, so their ratio is fair."""
    a()
    b()
    ta, tb = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        a()
        t1 = time.perf_counter()
        b()
        t2 = time.perf_counter()
        ta.append(t1 - t0)
        tb.append(t2 - t1)
    return statistics.median(ta), statistics.median(tb)


def _peak_bytes(fn: Callable[[], object]) -> int:
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def run(size: int, n_lights: int, repeats: int, tile_rows: int | None) -> str:
    lights = fibonacci_lights(n_lights)
    normals, _ = sphere_normals(size, size)
    images = render(normals, 0.6, lights, specular=0.8, shininess=60.0)
    images += np.random.default_rng(0).normal(0, 0.003, images.shape).astype(np.float32)
    # as captured, exposed so that nothing saturates (saturated pixels take the slower
    # per-pixel path, which is measured by the fit_session benchmark's real sessions)
    frames = list(np.clip(images / images.max() * 0.9 * 65535, 0, 65535).astype(np.uint16))
    pixels = size * size
    work = pixels * n_lights
    stack_bytes = images.nbytes
    flat = images.reshape(n_lights, -1)
    kwargs = {"tile_rows": tile_rows} if tile_rows else {}
    rows = []
    for name in MODELS:
        p = 3 if name.startswith("ps") else N_COEFFICIENTS[name]
        w = np.random.default_rng(1).normal(size=(p, n_lights)).astype(np.float32)
        t_mm, t_fit = _paired_times(
            lambda w=w: w @ flat,
            lambda name=name: fit_model(name, images, lights, **kwargs),
            repeats,
        )
        t_u16 = _median_time(lambda name=name: fit_model(name, frames, lights, **kwargs), repeats)
        peak = _peak_bytes(
            lambda name=name: fit_model(name, frames, lights, tile_rows=PEAK_TILE_ROWS)
        )
        rows.append((name, p, t_mm, t_fit, t_u16, peak))
        print(
            f"{name:10s} p={p:2d}  matmul {t_mm * 1e3:8.1f} ms  fit(float32) {t_fit * 1e3:8.1f} ms"
            f"  fit(uint16 frames) {t_u16 * 1e3:8.1f} ms  ratio {t_fit / t_mm:6.1f}x"
            f"  peak {peak / 1e6:7.1f} MB"
        )
    threads = os.environ.get("OPENBLAS_NUM_THREADS")
    cmd = (
        f"python -m benchmarks.fit_throughput --size {size} --lights {n_lights} --repeats {repeats}"
    )
    if threads:
        cmd = f"OPENBLAS_NUM_THREADS={threads} {cmd}"
    if tile_rows:
        cmd += f" --tile-rows {tile_rows}"
    lines = [
        "## Fit throughput (reconstruction models vs a plain matrix product)",
        "",
        f"{machine_line()} Command: `{cmd}`.",
        "",
        f"Shape: {size} × {size} grey pixels, {n_lights} lights (Fibonacci hemisphere), "
        f"synthetic sphere with highlights and noise; median of {repeats} runs after a warm-up. "
        '"matmul" is a float32 `(p × N) @ (N × pixels)` product, the same shape as the fit, '
        "timed alternately with the float32 fit in the same run (both see the same load; load "
        f"average at the start: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores). "
        "Throughput is pixels × lights per second. Peak memory is the "
        f"tracemalloc peak of one fit from uint16 frames in bands of {PEAK_TILE_ROWS} rows "
        f"(outputs included); the float32 stack would be {stack_bytes / 1e6:.0f} MB. Timings "
        "use the default band (256 MB budget).",
        "",
        "| model | coefficients | matmul (ms) | fit float32 (ms) | fit uint16 frames (ms) | "
        "fit throughput (Mpx·lights/s) | matmul throughput (Mpx·lights/s) | fit / matmul | "
        "peak memory (MB) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name, p, t_mm, t_fit, t_u16, peak in rows:
        lines.append(
            f"| {name} | {p} | {t_mm * 1e3:.1f} | {t_fit * 1e3:.1f} | {t_u16 * 1e3:.1f} | "
            f"{work / t_fit / 1e6:.0f} | {work / t_mm / 1e6:.0f} | {t_fit / t_mm:.1f}× | "
            f"{peak / 1e6:.0f} |"
        )
    return "\n".join(lines)


def accuracy(size: int, n_lights: int) -> str:
    """Accuracy on the same kind of scene: what the throughput buys (held-out lights)."""
    lights = fibonacci_lights(n_lights)
    normals, inside = sphere_normals(size, size)
    test = np.arange(n_lights) % 4 == 0
    lines = [
        "## Reconstruction accuracy on the synthetic sphere",
        "",
        f"{machine_line()} Written by `python -m benchmarks.fit_throughput` with "
        f"`--accuracy-size {size} --lights {n_lights}`.",
        "",
        f"{size} × {size} sphere, albedo 0.6, Blinn–Phong highlight of weight 0.8 at the given "
        f"shininess, noise σ = 0.003; {int((~test).sum())} Fibonacci lights fit, every 4th of "
        f"{n_lights} held out. Angular error over the sphere's valid pixels (valid fraction "
        "given); relighting PSNR (data range 1) and SSIM are means over held-out lights.",
        "",
        "| shininess | model | mean angle (°) | median (°) | valid | relight PSNR (dB) | "
        "relight SSIM |",
        "|---|---|---|---|---|---|---|",
    ]
    choices = []
    for shininess in (10.0, 40.0, 100.0):
        images = render(normals, 0.6, lights, specular=0.8, shininess=shininess)
        images += np.random.default_rng(2).normal(0, 0.003, images.shape).astype(np.float32)
        fit_im, fit_l, held_im, held_l = images[~test], lights[~test], images[test], lights[test]
        for name in MODELS:
            model = fit_model(name, fit_im, fit_l)
            angle = median = valid = "—"
            if name.startswith("ps"):
                ok = inside & model.valid
                stats = angular_error_deg(model.normals, normals, ok)
                angle, median = f"{stats.mean:.2f}", f"{stats.median:.2f}"
                valid = f"{ok.sum() / inside.sum():.3f}"
            elif name == "ptm":
                stats = angular_error_deg(model.normals(), normals, inside)
                angle, median = f"{stats.mean:.2f}", f"{stats.median:.2f}"
            lines.append(
                f"| {shininess:g} | {name} | {angle} | {median} | {valid} | "
                f"{relight_psnr(model, held_im, held_l):.2f} | "
                f"{relight_ssim(model, held_im, held_l):.4f} |"
            )
        choice = select_model(fit_im, fit_l)
        choices.append(f"- shininess {shininess:g}: `select_model` chose **{choice.model}**.")
    return "\n".join([*lines, "", *choices])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512, help="image side in pixels")
    parser.add_argument("--lights", type=int, default=48, help="number of lights N")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--accuracy-size", type=int, default=128, help="0 skips accuracy")
    parser.add_argument(
        "--tile-rows", type=int, default=None, help="rows per band (default: 256 MB budget)"
    )
    parser.add_argument(
        "--write", action="store_true", help="write the tables into docs/benchmarks.md"
    )
    args = parser.parse_args()
    markdown = run(args.size, args.lights, args.repeats, args.tile_rows)
    if args.write:
        print(f"written to {write_section('fit_throughput', markdown)}")
    if args.accuracy_size:
        table = accuracy(args.accuracy_size, args.lights)
        print(table)
        if args.write:
            write_section("reconstruction_accuracy", table)


if __name__ == "__main__":
    main()
