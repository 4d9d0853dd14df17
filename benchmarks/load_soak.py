"""Run a command N times in a row while CPU-bound processes run beside it; print the pass count.

Why: no test and no dry run may depend on CPU load (emulators on a pty are threads of the host's
process and must not race it). This is the evidence behind docs/reliability.md::

    python benchmarks/load_soak.py --hogs 2 --runs 20 --configs
    python benchmarks/load_soak.py --hogs 2 --runs 20 -- \
        .venv/bin/python -m pytest -q -p no:cacheprovider -m pty

``--configs`` runs ``rti-rig check`` on every simulated and emulated config in rig_configs/.
A run passes when its exit code is 0. The hogs (``while True: pass``) are this script's own
children and are killed when it ends, whatever happens.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
HOG = "while True: pass"


def soak(command: list[str], runs: int) -> tuple[int, list[str]]:
    """(passes, tail of each failure's output)."""
    passes, failures = 0, []
    for i in range(runs):
        r = subprocess.run(command, cwd=REPO, capture_output=True, text=True)
        if r.returncode == 0:
            passes += 1
            print(f"  run {i + 1}/{runs}: pass", flush=True)
            continue
        lines = (r.stdout + r.stderr).strip().splitlines()
        tail = [ln for ln in lines if ln.startswith(("FAILED", "ERROR", "RESULT", "ABORTED"))]
        failures.append(f"run {i + 1}: exit {r.returncode}\n" + "\n".join(tail or lines[-4:]))
        print(f"  run {i + 1}/{runs}: FAIL\n" + "\n".join(lines[-40:]), flush=True)
    return passes, failures


def dry_run_configs() -> list[Path]:
    """Every config in rig_configs/ that needs no hardware."""
    out = []
    for path in sorted((REPO / "rig_configs").glob("*.toml")):
        backend = tomllib.loads(path.read_text(encoding="utf-8")).get("backend", "simulated")
        if backend in ("simulated", "emulated"):
            out.append(path)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--hogs", type=int, default=2, help="CPU-bound processes beside it")
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument(
        "--configs", action="store_true", help="rti-rig check on every dry-run config"
    )
    parser.add_argument("command", nargs="*", help="the command (after --)")
    args = parser.parse_args()
    if not args.configs and not args.command:
        parser.error("give a command after -- or --configs")
    cli = str(Path(sys.executable).with_name("rti-rig"))
    commands = (
        [[cli, "check", str(p.relative_to(REPO))] for p in dry_run_configs()]
        if args.configs
        else [args.command]
    )
    hogs = [subprocess.Popen([sys.executable, "-c", HOG]) for _ in range(args.hogs)]
    results = []
    try:
        time.sleep(0.5)  # let the hogs get going
        for command in commands:
            print(f"{' '.join(command)}  ({args.hogs} CPU hogs beside it)", flush=True)
            started = time.monotonic()
            passes, failures = soak(command, args.runs)
            results.append((command, passes, time.monotonic() - started))
            for f in failures:
                print(f, flush=True)
    finally:
        for h in hogs:
            h.kill()
            h.wait()
    print("\nsummary")
    for command, passes, seconds in results:
        print(f"  {passes}/{args.runs} passed in {seconds:.0f} s: {' '.join(command)}")
    return 0 if all(p == args.runs for _, p, _ in results) else 1


if __name__ == "__main__":
    sys.exit(main())
