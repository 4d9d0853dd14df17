"""What the benchmarks that measure through the front door share: ``rti-rig`` run as a user
runs it (a new process), a shipped rig config with its scene changed, every scene, and the
command line of a benchmark that shoots sessions.

Why one module: benchmarks.qa_underexposed and benchmarks.qa_likeness had each written the
first two (the scene's pattern twice over, to drift apart), and qa_turn
the last two again."""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ROOT / "rig_configs"


def rti_rig(*args: str) -> subprocess.CompletedProcess[str]:
    """``rti-rig ARGS`` in a new process (as a user runs it), its output kept."""
    env = dict(os.environ, COLUMNS="400")
    cmd = [sys.executable, "-m", "rti_rig", *args]
    return subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True, check=False)


def shipped_with_scene(rig: str, scene: str) -> str:
    """The text of ``rig_configs/<rig>`` with its ``[scene]`` named ``scene``; exits naming the
    config where it has no ``[scene]`` name to change (a shipped config that changed must not
    measure another scene quietly)."""
    text = (CONFIGS / rig).read_text(encoding="utf-8")
    text, n_scene = re.subn(r'(?ms)(\[scene\].*?^name = )"[^"]*"', rf'\g<1>"{scene}"', text)
    if n_scene != 1:
        raise SystemExit(f"{rig}: no [scene] name to vary")
    return text


def sessions_args(doc: str, argv: list[str] | None, lights: int) -> argparse.Namespace:
    """The command line of a benchmark that shoots sessions of ``lights`` lights (``--lights``)
    and writes its figures to docs/reconstruction.md when asked (``--write``); ``doc``: the
    benchmark's docstring, whose first line ``--help`` says."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument(
        "--lights", type=int, default=lights, help=f"lights per session (default {lights})"
    )
    ap.add_argument(
        "--write", action="store_true", help="update the figures in docs/reconstruction.md"
    )
    return ap.parse_args(argv)


def every_scene() -> tuple[str, ...]:
    """The shipped configs' built-in scene (``relief``) and every scene of the library."""
    from rti_rig.simulator.scenes import SCENE_NAMES

    return ("relief", *SCENE_NAMES)
