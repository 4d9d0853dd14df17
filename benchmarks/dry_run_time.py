"""README's first command, timed: ``rti-rig run rig_configs/simulated_dome.toml --out DIR``.

Each run is a whole new process (``python -m rti_rig run ...`` in a fresh output folder), so
what a user pays is what is measured: the imports, the capture (the simulated camera renders
and exposes every light, the session writes its files) and the QA verdict (which loads the
robust fit's compiled kernel). The process runs the CLI through a small wrapper that times
those stages on both clocks: wall (what the user waits, and what a loaded machine stretches)
and CPU (``time.process_time``: every thread of the process, little moved by load). The
median of ``--runs`` runs (at least 3) is printed for each stage.

``--cold``: numba's cache is pointed at an empty folder for every run, so the kernel is
compiled inside the verdict, as on the first run after an install.

Run: ``python -m benchmarks.dry_run_time [--runs N] [--cold] [--write]`` (prints; ``--write``
updates docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CONFIG = ROOT / "rig_configs" / "simulated_dome.toml"
STAGES = ("import", "capture", "verdict", "total")

#: Runs in the measured process: wraps the capture and the verdict with both clocks, then runs
#: the CLI as ``python -m rti_rig`` does; the figures go to the JSON file named by argv[1].
_WRAPPER = r"""
import json, sys, time
w0, c0 = time.perf_counter(), time.process_time()
figures = {}
def timed(stage, fn):
    def wrapped(*a, **k):
        w, c = time.perf_counter(), time.process_time()
        try:
            return fn(*a, **k)
        finally:
            figures[stage] = (time.perf_counter() - w, time.process_time() - c)
    return wrapped
import rti_rig.cli.fit as cli_fit
import rti_rig.app.usecases.session as usecase
from rti_rig.launch import main
figures["import"] = (time.perf_counter() - w0, time.process_time() - c0)
usecase.run_opened_session = timed("capture", usecase.run_opened_session)
cli_fit.print_verdict = timed("verdict", cli_fit.print_verdict)
out = sys.argv.pop(1)
sys.argv[0] = "rti-rig"
try:
    main()
except SystemExit as exc:
    figures["exit"] = exc.code
finally:
    figures["total"] = (time.perf_counter() - w0, time.process_time() - c0)
    with open(out, "w") as f:
        json.dump(figures, f)
"""


def one_run(scratch: Path, index: int, cold: bool) -> dict[str, tuple[float, float]]:
    """One dry run in a new process; its stages' (wall, CPU) seconds."""
    env = dict(os.environ, COLUMNS="200")
    if cold:
        env["NUMBA_CACHE_DIR"] = str(scratch / f"numba_{index}")
    figures = scratch / f"figures_{index}.json"
    cmd = [sys.executable, "-c", _WRAPPER, str(figures), "run", str(CONFIG)]
    cmd += ["--out", str(scratch / f"S{index}")]
    done = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True, check=False)
    if done.returncode != 0 or not figures.exists():
        raise SystemExit(f"the dry run failed (exit {done.returncode}):\n{done.stderr[-2000:]}")
    got = json.loads(figures.read_text())
    return {stage: tuple(got[stage]) for stage in STAGES}  # type: ignore[misc]


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--cold", action="store_true", help="compile the kernel in every run")
    ap.add_argument("--write", action="store_true", help="update docs/benchmarks.md")
    args = ap.parse_args(argv)
    if args.runs < 3:
        ap.error("--runs: at least 3 (the figures are medians)")
    load_before = os.getloadavg()[0]
    runs = []
    with tempfile.TemporaryDirectory(prefix="dry_run_time_") as tmp:
        for i in range(args.runs):
            runs.append(one_run(Path(tmp), i, args.cold))
            total = runs[-1]["total"]
            print(f"run {i + 1}: {total[0]:.1f} s wall, {total[1]:.1f} s CPU", flush=True)
    rows = []
    for stage in STAGES:
        wall = statistics.median(r[stage][0] for r in runs)
        cpu = statistics.median(r[stage][1] for r in runs)
        rows.append(f"| {stage} | {wall:.1f} | {cpu:.1f} |")
    load = f"load average (1 min) {load_before:.1f} before, {os.getloadavg()[0]:.1f} after"
    kernel = "compiled in every run (--cold)" if args.cold else "loaded from numba's cache"
    from benchmarks.report import machine_line, write_section

    md = "\n".join(
        [
            "## The dry run, README's first command (`python -m benchmarks.dry_run_time`)",
            "",
            machine_line(),
            "",
            f"`rti-rig run rig_configs/simulated_dome.toml` (48 lights, 512 px), each run a new "
            f"process; median of {args.runs} runs; the robust kernel {kernel}; {load}, on "
            f"{os.cpu_count()} cores shared with other jobs. *Wall* is what "
            "the user waits (a loaded machine stretches it); *CPU* is `process_time`. *Total* "
            "includes the imports and the session summary.",
            "",
            "| stage | wall s | CPU s |",
            "|---|---|---|",
            *rows,
        ]
    )
    print(md)
    if args.write:
        write_section("dry_run_time", md)
    return md


if __name__ == "__main__":
    main()
