"""A map of a light plan: where its lights sit over the object, numbered in firing order.

Why: a plan is checked before anything moves. Lights crowded on one side, a gap where the
object's relief faces, a light near the camera axis over a gilded object, an arm's plan hugging
its limits: a map shows these at a glance, where an ``.lp`` listing of vectors does not.

The map is the view from above in the frame of docs/conventions.md: the zenith (the camera axis)
at the centre, the horizon at the rim, azimuth 0° (+x) to the right and 90° (+y) up; the distance
from the centre is 90° minus the elevation.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.errors import RtiRigError
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.core.shell_words import shown_path

#: File types the map can be written as (by the file name's suffix).
FIGURE_SUFFIXES = (".png", ".svg", ".pdf")

#: Marker areas (points²) of a planned light and of the preview's light, which is drawn under
#: it and larger, so that a planned light at the preview's position keeps its number visible.
LIGHT_SIZE = 150
PREVIEW_STAR_SIZE = 520
#: The preview star's size in the legend (the map's own is larger, to show around a light).
LEGEND_STAR_SIZE = 220


def polar_coordinates(directions: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(angle in radians = azimuth, radius = 90° − elevation) of unit light directions."""
    az, el = az_el_from_direction(np.asarray(directions, dtype=np.float64).reshape(-1, 3))
    return np.radians(np.atleast_1d(az)), 90.0 - np.atleast_1d(el)


def _draw_arm_reach(ax: Axes, arm: ArmGeometry) -> None:
    """Shade the band of directions the arm may reach and hatch its keep-out cone."""
    theta = np.radians(np.linspace(arm.min_azimuth_deg, arm.max_azimuth_deg, 181, dtype=float))
    inner, outer = 90.0 - arm.max_elevation_deg, 90.0 - arm.min_elevation_deg
    ax.fill_between(
        theta, inner, outer, color="tab:green", alpha=0.12, label="arm's reach", gid="reach"
    )
    keep = arm.keep_out_half_angle_deg
    if keep > 0:
        full = np.linspace(0.0, 2 * np.pi, 181)
        ax.fill(
            full,
            np.full_like(full, keep),
            facecolor="none",
            edgecolor="tab:red",
            hatch="//",
            label="keep-out cone",
            gid="keep_out",
        )


def layout_figure(
    chosen: ArrayLike,
    geometry: DomeGeometry | ArmGeometry,
    preview: ArrayLike | None = None,
    title: str = "",
    caption: Sequence[str] = (),
    min_elevation_deg: float = 0.0,
    max_elevation_deg: float = 90.0,
) -> Figure:
    """The map of ``chosen`` (N×3 directions, in firing order) on ``geometry``.

    A dome's LEDs are grey dots; an arm's reachable band is shaded and its keep-out cone
    hatched. The chosen lights are numbered 1…N; ``preview`` (the preview's light) is a star,
    drawn under them so that a light planned at the preview's place keeps its number.
    An elevation floor above 0° (``--min-elevation-deg``) and a ceiling below 90°
    (``--max-elevation-deg``) are dashed and dotted rings: the planner took no light outside
    them, so LEDs there were excluded on purpose, not overlooked.
    """
    fig = Figure(figsize=(6.4, 7.0), layout="constrained")
    ax = fig.add_subplot(projection="polar")
    ax.set_theta_zero_location("E")  # azimuth 0° = +x to the right
    ax.set_theta_direction(1)  # counter-clockwise, towards +y
    ax.set_rlim(0.0, 90.0)
    ax.set_rticks([30, 60, 90])
    ax.set_yticklabels(["60°", "30°", ""])  # elevations: the rim is 0°, the centre 90°
    ax.set_rlabel_position(292.5)  # away from the default preview light's side (135°)
    ax.grid(True, alpha=0.4)
    if isinstance(geometry, DomeGeometry):
        t, r = polar_coordinates(geometry.directions)
        ax.scatter(t, r, s=14, c="0.7", label=f"dome LEDs ({len(t)})", zorder=2, gid="candidates")
    else:
        _draw_arm_reach(ax, geometry)
    ring = np.linspace(0.0, 2 * np.pi, 361)
    for limit, shown, label, gid in (
        (min_elevation_deg, min_elevation_deg > 0, "elevation floor", "floor"),
        (max_elevation_deg, max_elevation_deg < 90, "elevation ceiling", "ceiling"),
    ):
        if shown:
            ax.plot(
                ring,
                np.full_like(ring, 90.0 - limit),
                color="tab:purple",
                ls="--" if gid == "floor" else ":",
                lw=1.2,
                zorder=3,
                label=f"{label} {limit:g}°",
                gid=gid,
            )
    t, r = polar_coordinates(chosen)
    ax.plot(t, r, color="tab:blue", alpha=0.35, lw=1, zorder=3)  # the firing order
    ax.scatter(t, r, s=LIGHT_SIZE, c="tab:blue", edgecolors="white", zorder=4, gid="chosen")
    for i, (ti, ri) in enumerate(zip(t, r, strict=True), start=1):
        ax.text(ti, ri, str(i), color="white", fontsize=7, ha="center", va="center", zorder=5)
    if preview is not None:
        # under the planned lights and larger than them: the default plans often fire the
        # preview's own LED again, and that light's number must stay readable (its star's
        # points show around it)
        pt, pr = polar_coordinates(preview)
        ax.scatter(
            pt,
            pr,
            s=PREVIEW_STAR_SIZE,
            marker="*",
            c="tab:orange",
            zorder=3.5,
            gid="preview",
        )
        ax.scatter([], [], s=LEGEND_STAR_SIZE, marker="*", c="tab:orange", label="preview light")
    ax.scatter([], [], s=60, c="tab:blue", label=f"planned lights ({len(t)}), in firing order")
    fig.legend(loc="outside lower center", ncol=2, fontsize=8, frameon=False)
    if title:
        fig.suptitle(title, fontsize=10, parse_math=False)  # a file name may hold "$"
    notes = [
        "seen from above: azimuth 0° (+x) right, 90° (+y) up; "
        "rings at 60° and 30° elevation, rim 0°",
        *caption,
    ]
    wrapped = [w for note in notes for w in textwrap.wrap(note, 110)]
    ax.set_title("\n".join(wrapped), fontsize=7, pad=22, parse_math=False)
    return fig


def expected_caption(meaning: str, expected: dict[str, float]) -> str:
    """One short line from a plan report's expected errors: the plan's own value and the best
    layout it was compared with (the full list is in the report the command prints)."""
    if not expected:
        return ""
    if "optimal" in expected and len(expected) > 1:
        others = {k: v for k, v in expected.items() if k != "optimal"}
        best = min(others, key=lambda k: others[k])
        mine = expected["optimal"]
        return f"{meaning}: optimal {mine:#.4g}, best starting layout ({best}) {others[best]:#.4g}"
    return f"{meaning}: " + ", ".join(f"{k} {v:#.4g}" for k, v in expected.items())


def check_figure_path(path: Path) -> None:
    """Refuse a map file type that cannot be written, before any planning is done."""
    if path.suffix.lower() not in FIGURE_SUFFIXES:
        raise RtiRigError(
            f"--figure {shown_path(path)}: give a file ending in {', '.join(FIGURE_SUFFIXES)} (the "
            "map's format follows the name)"
        )


def write_layout_figure(path: Path, figure: Figure) -> Path:
    """Write ``figure`` to ``path`` (format from the suffix, see :data:`FIGURE_SUFFIXES`)."""
    check_figure_path(path)
    # atomically, as the plan itself: a Ctrl-C while matplotlib wrote the file had left a
    # partial map under the name asked, which the next run refused to replace without --force
    tmp = path.with_name(f".{path.stem}.partial{path.suffix}")
    try:
        figure.savefig(tmp, dpi=150, format=path.suffix.lower().lstrip("."))
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)
    return path
