"""Where the QA verdict's CPU goes: :func:`rti_rig.reconstruct.qa.assess` on one session.

The verdict ``rti-rig run`` prints after its capture (and ``rti-rig fit`` after its fit) is
this call; on README's first command (the simulated 48-LED dome, 512 px) it was most of what
followed the capture. CPU time (``time.process_time``: every thread of this process), not the
wall clock, so a loaded machine moves the figures little; the profile is taken on the same
clock, and its top entries by cumulative time are printed.

Run: ``python -m benchmarks.qa_time [SESSION] [--top N]`` (SESSION: a session folder, e.g.
one written by ``python -m rti_rig run rig_configs/simulated_dome.toml --out S``; without
it, a rendered 48-light sphere of 512 px). The robust kernel is loaded before timing.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time
from pathlib import Path
from typing import Any

import numpy as np

from rti_rig.app.usecases.fit import load_acquisition
from rti_rig.reconstruct.qa import assess
from rti_rig.reconstruct.robust_ps import warm_up
from rti_rig.reconstruct.synthetic import sphere_frames


def rendered(n: int = 48, side: int = 512) -> tuple[list[Any], np.ndarray, list[str]]:
    """A still, correctly lit sphere of ``n`` lights (uint16 RGB, a little noise)."""
    frames, lights = sphere_frames(n, side)
    return frames, lights, [f"image_{i + 1:03d}" for i in range(n)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("session", nargs="?", type=Path)
    ap.add_argument("--top", type=int, default=15)
    args = ap.parse_args()
    if args.session is not None:
        frames, lights, names, what = load_acquisition(args.session)
    else:
        frames, lights, names = rendered()
        what = f"{len(frames)} rendered images"
    warm_up()
    t0 = time.process_time()
    report = assess(frames, lights, names)
    cpu = time.process_time() - t0
    print(f"{what}: assess {cpu:.2f} s CPU, verdict {report.verdict[:60]}")
    prof = cProfile.Profile(time.process_time)
    prof.enable()
    assess(frames, lights, names)
    prof.disable()
    stats = pstats.Stats(prof)
    stats.sort_stats("cumulative").print_stats(args.top)


if __name__ == "__main__":
    main()
