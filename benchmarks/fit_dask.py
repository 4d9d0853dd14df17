"""A batch of sessions fitted in one process vs on a local two-worker Dask distributed cluster.

Issue #29 asks for "a batch of sessions on a local two-worker Dask distributed cluster against
the single-process time". This script writes N simulated sessions (the glossy sphere of
:mod:`benchmarks.fit_session`, 16-bit linear TIFFs as `rti-rig run` writes them), then times,
as whole `rti-rig fit S1 … SN --out ROOT` processes (outputs written, default options: model
choice, normals, .ptm, .rti, QA):

* **single process** — no ``--scheduler``: sessions one after another;
* **Dask threads** — ``--scheduler threads``: sessions one after another, bands in threads;
* **cluster** — ``--scheduler ADDRESS`` of a ``distributed.LocalCluster(n_workers=2,
  threads_per_worker=1, processes=True)`` started once before the runs (a cluster is long-lived,
  so its start-up is reported apart, not counted): sessions as parallel tasks.

Each mode runs ``--repeats`` times, interleaved; medians are reported with the load average
before and after. Every run's outputs are checked byte-identical to the single-process ones
(normals, albedo, .ptm, .rti). The machine this project runs on has 2 cores shared with other
jobs: the ratio is noisy, read it with the load average.

Run: ``python -m benchmarks.fit_dask [--sessions 4 --width 512 --height 384 --lights 48
--repeats 3]``; ``--write`` puts the table into docs/benchmarks.md (section ``fit_dask``).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks.fit_session import make_session
from benchmarks.report import machine_line, write_section

COMPARED = ("normals.npy", "normals.png", "albedo.npy", "albedo.png", "fit.ptm", "fit.rti")


def run_batch(sessions: list[Path], out: Path, extra: list[str], env: dict[str, str]) -> float:
    """Wall time of one `rti-rig fit` batch process."""
    cmd = [sys.executable, "-m", "rti_rig", "fit", *map(str, sessions), "--out", str(out), *extra]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=env, timeout=3600)
    return time.perf_counter() - t0


def differing(reference: Path, other: Path, sessions: list[Path]) -> list[str]:
    """Output files whose bytes differ from the single-process batch's."""
    bad = []
    for s in sessions:
        for name in COMPARED:
            a, b = reference / s.name / name, other / s.name / name
            if a.exists() and a.read_bytes() != b.read_bytes():
                bad.append(f"{s.name}/{name}")
    return bad


def load() -> str:
    one, five, _ = os.getloadavg()
    return f"{one:.1f} (1 min) / {five:.1f} (5 min)"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sessions", type=int, default=4)
    parser.add_argument("--width", type=int, default=512)
    parser.add_argument("--height", type=int, default=384)
    parser.add_argument("--lights", type=int, default=48)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument(
        "--blas-threads",
        type=int,
        default=1,
        help="OPENBLAS/OMP/MKL_NUM_THREADS of every rti-rig process (0: the library default)",
    )
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()

    env = dict(os.environ)  # before LocalCluster sets OMP/OPENBLAS_NUM_THREADS=1 in ours
    if args.blas_threads > 0:
        for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
            env[var] = str(args.blas_threads)
    work = Path(tempfile.mkdtemp(prefix="fit_dask_bench_"))
    try:
        sessions = [
            make_session(work / f"session_{k + 1}", args.width, args.height, args.lights)
            for k in range(args.sessions)
        ]
        from distributed import LocalCluster

        t0 = time.perf_counter()
        cluster = LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        )
        startup = time.perf_counter() - t0
        # a cluster is long-lived: its workers have imported the fit before a batch arrives
        warm = [make_session(work / f"warm_{k}", 32, 24, args.lights) for k in range(2)]
        run_batch(warm, work / "warm_out", ["--scheduler", cluster.scheduler_address], env)
        load_before = load()
        modes = {
            "single process": [],
            "Dask threads (`--scheduler threads`)": ["--scheduler", "threads"],
            "local cluster, 2 workers × 1 thread": ["--scheduler", cluster.scheduler_address],
        }
        times: dict[str, list[float]] = {m: [] for m in modes}
        mismatches: dict[str, list[str]] = {m: [] for m in modes}
        reference = work / "out_ref"
        try:
            for r in range(args.repeats):
                for k, (mode, extra) in enumerate(modes.items()):
                    out = work / f"out_{r}_{k}"
                    times[mode].append(run_batch(sessions, out, extra, env))
                    if r == 0 and k == 0:
                        out.rename(reference)
                    else:
                        mismatches[mode] += differing(reference, out, sessions)
                        shutil.rmtree(out)
                    print(f"run {r + 1}: {mode:40s} {times[mode][-1]:7.1f} s", flush=True)
        finally:
            cluster.close()
        load_after = load()
    finally:
        shutil.rmtree(work, ignore_errors=True)

    base = statistics.median(times["single process"])
    mp = args.width * args.height / 1e6
    lines = [
        "## `rti-rig fit` batch: one process vs a local two-worker Dask cluster",
        "",
        f"{machine_line()} Command: `python -m benchmarks.fit_dask --sessions {args.sessions} "
        f"--width {args.width} --height {args.height} --lights {args.lights} "
        f"--repeats {args.repeats} --blas-threads {args.blas_threads}`.",
        "",
        f"A batch of {args.sessions} simulated sessions ({args.lights} RGB 16-bit TIFFs of "
        f"{args.width} × {args.height}, {mp:.2f} MP; default options: model choice, normals, "
        "`.ptm`, `.rti`, QA), each mode one `rti-rig fit S1 … SN --out ROOT` process, wall "
        f"time, median of {args.repeats} interleaved runs. The cluster "
        "(`distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True)`) was "
        f"started once before the runs ({startup:.1f} s, not counted) and warmed up with a "
        "batch of two tiny sessions (its workers import the fit once); on it each session is "
        "one task. BLAS threads of every process: "
        f"{args.blas_threads or 'library default'} (the cluster's workers use the client's "
        "count, for identical outputs). Load average before / after: "
        f"{load_before} → {load_after}, on 2 cores shared with other jobs — the ratios are "
        "noisy: a busy machine leaves the second worker little to run on.",
        "",
        "| mode | median wall (s) | runs (s) | ratio to single process | outputs identical |",
        "|---|---|---|---|---|",
    ]
    for mode in modes:
        med = statistics.median(times[mode])
        runs = ", ".join(f"{t:.1f}" for t in times[mode])
        same = (
            "reference"
            if mode == "single process"
            else (
                "yes" if not mismatches[mode] else f"NO: {', '.join(sorted(set(mismatches[mode])))}"
            )
        )
        lines.append(f"| {mode} | {med:.1f} | {runs} | {med / base:.2f} | {same} |")
    table = "\n".join(lines)
    print(table)
    written = write_section("fit_dask", table)  # only with --write
    if written:
        print(f"written to {written}")


if __name__ == "__main__":
    main()
