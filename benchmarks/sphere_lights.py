"""Light directions from a sphere (``rti-rig lights-from-sphere``) against the truth.

The path a new dome takes: the shipped emulated dome (real driver, pyserial, firmware emulator
on a pty) with a stand-in layout (``layout = "fibonacci"``, 48 LEDs) shoots the ``sphere``
scene while its emulated LEDs are really where ``rig_configs/example_dome_48.lp`` says (point
lamps at 400 mm); the command measures the directions from the images and the angle to the
file's is printed, median and worst, per image size, with the lamps at the shipped 400 mm and
at 400 m. Why both: the method takes the light as distant, but the highlight sits on the
sphere's surface, not at the object's centre, so near lamps are seen from a point a few mm
off (the sphere's parallax); far lamps leave the measurement's own error. Prints only (no
docs section).

Run: ``python -m benchmarks.sphere_lights [--sizes 160 320]``.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import directions_of, read_lp
from rti_rig.simulator.scenes import sphere_circle

CONFIGS = Path(__file__).resolve().parents[1] / "rig_configs"
TRUTH = CONFIGS / "example_dome_48.lp"


def new_dome_config(folder: Path, side: int, distance_mm: float = 400.0) -> Path:
    """The emulated dome with a stand-in layout, its LEDs really at ``TRUTH``."""
    text = (CONFIGS / "emulated_dome.toml").read_text(encoding="utf-8")
    for old, new in (
        ('layout = "lp"\nlp_file = "example_dome_48.lp"', 'layout = "fibonacci"\ncount = 48'),
        ("width = 256", f"width = {side}"),
        ("height = 256", f"height = {side}"),
        ('name = "tablet"', 'name = "sphere"'),
        ("light_distance_mm = 400.0", f"light_distance_mm = {distance_mm}"),
    ):
        assert old in text, f"emulated_dome.toml: {old!r}"
        text = text.replace(old, new)
    config = folder / "new_dome.toml"
    config.write_text(f'{text}\n[emulator]\nled_directions_file = "{TRUTH}"\n', encoding="utf-8")
    return config


def measure(side: int, distance_mm: float = 400.0) -> tuple[float, float, float]:
    """Median and worst angle (degrees) of the measured directions at ``side`` px with the
    lamps ``distance_mm`` away, and the sphere's radius in px."""
    runner = CliRunner()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        session, lp = folder / "sphere_session", folder / "my_dome.lp"
        r = runner.invoke(
            app,
            [
                "run",
                str(new_dome_config(folder, side, distance_mm)),
                "--out",
                str(session),
                "--no-verdict",
            ],
        )
        assert r.exit_code == 0, r.output
        x, y, radius = sphere_circle(side, side)
        r = runner.invoke(
            app,
            ["lights-from-sphere", str(session), "--sphere", f"{x},{y},{radius}", "--out", str(lp)],
        )
        assert r.exit_code == 0, r.output
        dot = (directions_of(read_lp(lp)) * directions_of(read_lp(TRUTH))).sum(1)
        errors = np.degrees(np.arccos(np.clip(dot, -1.0, 1.0)))
    return float(np.median(errors)), float(errors.max()), radius


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[160, 320])
    args = parser.parse_args(argv)
    lines = [
        "| image px | sphere radius px | lamps at mm | median error ° | worst error ° |",
        "|---|---|---|---|---|",
    ]
    for side in args.sizes:
        for distance_mm in (400.0, 400_000.0):
            median, worst, radius = measure(side, distance_mm)
            lines.append(
                f"| {side} | {radius:.0f} | {distance_mm:g} | {median:.2f} | {worst:.2f} |"
            )
    text = "\n".join(lines)
    print(text)
    return text


if __name__ == "__main__":
    main()
