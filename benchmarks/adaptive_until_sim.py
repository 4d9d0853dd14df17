"""``--until-error`` on the simulator's scenes: does the measured error fall as lights are added,
and is the estimate honest where the session stops?

One session per scene (all 240 candidates, capped at ``--cap`` lights, N unknown: as
``rti-rig run RIG --until-error DEG`` without ``--lights``), run to the cap with a target that
is never reached; a decision does not depend on the target (only the stop does), so the session
that stops at target T is this one's prefix up to the first light count whose estimate is ≤ T.
Printed per scene: the estimate and the error measured against the scene's true normals after
k lights (k = 6, 9, 12, 18, 27, 40, 60), and per target the stop: lights used, estimate,
measured, measured / estimate. ``--greedy`` runs the bound's best light one at a time (format
5's path) for comparison; ``--scale`` overrides the estimate's factor (default
``SIM_ESTIMATE_SCALE``). The leave-one-scene-out factor for the light-by-light path: least
squares of log measured / raw estimate over every light count k ≥ 6 of the other scenes.

Run: ``python -m benchmarks.adaptive_until_sim [--scenes a,b] [--cap 60] [--greedy]
[--targets 1,2,4] [--write]`` (``--write`` puts the tables into docs/adaptive.md).

Per target, three stops are replayed: on the point estimate (format 7), on the point × the
factor alone (format 8, the rule the factor was derived on) and as the stop ships since
2026-12-06 (``planner.adaptive_until.upper_error_deg``: the larger of the point × the factor
and the images' misfit bound, plus the unsolved share × ``UNSOLVED_DEG``). Both image terms
are read on the scene's 96-px images, which are the camera's here; ``--traces`` keeps them
after every light count for ``benchmarks.adaptive_until_bound``.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from benchmarks.adaptive import adaptive_run
from benchmarks.report import machine_line, write_section
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.adaptive import SIM_ESTIMATE_SCALE
from rti_rig.planner.adaptive_until import UPPER_FACTOR, upper_error_deg

DOC = Path(__file__).resolve().parent.parent / "docs" / "adaptive.md"
CHECK = (6, 9, 12, 18, 27, 40, 60)
NEVER = 1e-6  # a target no estimate reaches


def session(scene: str, cap: int, draw: int = 0, seed: int = 0) -> dict:
    """One capped session on ``scene``: used lights, estimate after k, measured after k.

    Draw 0 offers all 240 candidates; draw d > 0 has ``SIM_REMOVED`` of them out (drawn with
    ``seed``, per scene), as ``benchmarks.adaptive``'s simulator draws."""
    from benchmarks.adaptive import SIM_REMOVED
    from benchmarks.tradeoff import TradeoffSettings, normal_error, render_scene_data

    settings = TradeoffSettings(held_out_lights=1, ground_truth_lights=50)
    data = render_scene_data(scene, settings)
    cand_all = data.candidate_dirs
    keep = np.arange(len(cand_all))
    if draw > 0:
        si = settings.scenes.index(scene)
        rng = np.random.default_rng([seed, si, draw])
        keep = np.sort(rng.choice(len(cand_all), len(cand_all) - SIM_REMOVED, replace=False))
    cand = cand_all[keep]
    images = data.candidate_images[keep]
    grey = images.mean(axis=-1)
    full = DomeGeometry(cand, tuple(f"c{i:03d}" for i in keep))
    t0 = time.perf_counter()
    terms: dict[str, dict[int, float | None]] = {}
    used, est, dt = adaptive_run(grey, cand, full, cap, until=NEVER, scale=1.0, image_terms=terms)
    seconds = time.perf_counter() - t0
    idx = np.array(used)
    measured = {
        k: normal_error(data.normals, images[idx[:k]], cand[idx[:k]])[0]
        for k in range(4, len(used) + 1)
    }
    raw = {k: v for k, v in est.items() if isinstance(k, int)}
    elev = np.degrees(np.arcsin(np.clip(cand[idx, 2], -1, 1)))
    return {
        "scene": scene,
        "draw": draw,
        "used": used,
        "raw": raw,
        "measured": measured,
        "misfit": terms.get("misfit", {}),
        "unsolved": terms.get("unsolved", {}),
        "elev": elev,
        "decision_s": dt,
        "seconds": seconds,
    }


def _name(s: dict) -> str:
    return s["scene"] if not s.get("draw") else f"{s['scene']} #{s['draw']}"


def save_traces(path: Path, sessions: list[dict]) -> None:
    """Each session's raw estimate (simulated error, factor 1), measured error and the stop's
    two image terms (the misfit bound in degrees, the unsolved share; null where the images
    gave none) per light count, as JSON (``benchmarks.adaptive_until_bound`` reads it)."""
    import json

    rows = [
        {
            "scene": s["scene"],
            "draw": s["draw"],
            "used": [int(u) for u in s["used"]],
            "raw": {str(k): float(v) for k, v in s["raw"].items()},
            "measured": {str(k): float(v) for k, v in s["measured"].items()},
            "misfit": {str(k): _opt(v) for k, v in s.get("misfit", {}).items()},
            "unsolved": {str(k): _opt(v) for k, v in s.get("unsolved", {}).items()},
        }
        for s in sessions
    ]
    path.write_text(json.dumps({"source": "sim", "sessions": rows}, indent=1))


def _opt(v: float | None) -> float | None:
    return None if v is None else float(v)


def shipped_upper(s: dict, k: int, scale: float, factor: float) -> float:
    """The upper estimate the shipped stop compares after ``k`` lights
    (``planner.adaptive_until.upper_error_deg``): the larger of the point estimate × ``factor``
    and the images' misfit bound, plus the unsolved share × ``UNSOLVED_DEG``."""
    return upper_error_deg(
        scale * s["raw"][k],
        factor,
        s.get("unsolved", {}).get(k) or 0.0,
        None,
        s.get("misfit", {}).get(k),
    )


def loo_scales(sessions: list[dict]) -> dict[str, float]:
    """Per scene: the factor fitted on the other scenes (log least squares, k ≥ 6)."""
    pairs: dict[str, list[tuple[float, float]]] = {}
    for s in sessions:
        pairs.setdefault(s["scene"], []).extend(
            (s["raw"][k], s["measured"][k]) for k in s["measured"] if k >= 6 and k in s["raw"]
        )
    out = {}
    for scene in pairs:
        logs = [np.log(m / r) for o, ps in pairs.items() if o != scene for r, m in ps if r > 0]
        out[scene] = float(np.exp(np.mean(logs))) if logs else float("nan")
    allp = [np.log(m / r) for ps in pairs.values() for r, m in ps if r > 0]
    out["all"] = float(np.exp(np.mean(allp))) if allp else float("nan")
    return out


def stop_at(
    s: dict, target: float, scale: float, cap: int, upper: float = 1.0, shipped: bool = False
) -> tuple[int, float | None]:
    """Lights used and the upper estimate at the stop: the first light count whose upper
    estimate is at most ``target`` (else the session's end). The upper estimate is the point
    estimate (``scale`` × raw) × ``upper``, or with ``shipped`` the shipped stop's
    (:func:`shipped_upper`: the images' misfit bound and unsolved share weighed too)."""

    def up(k: int) -> float:
        if shipped:
            return shipped_upper(s, k, scale, upper)
        return upper * scale * s["raw"][k]

    for k in sorted(s["raw"]):
        if up(k) <= target:
            return k, up(k)
    k = len(s["used"])
    return k, (up(k) if k in s["raw"] else None)


def report(
    sessions: list[dict],
    targets: tuple[float, ...],
    scale: float,
    cap: int,
    cmd: str,
    elapsed: float,
    greedy: bool,
    upper: float = UPPER_FACTOR,
) -> str:
    loo = loo_scales(sessions)
    how = (
        "the bound's best light one at a time (format 5)"
        if greedy
        else ("within the design for a guessed N that grows (planner/adaptive_until.py)")
    )
    lines = [
        f"Command: `{cmd}` ({elapsed:.0f} s; load average {os.getloadavg()[0]:.1f} at the end). "
        f"{machine_line()}",
        "",
        f"Light by light, {how}; all 240 candidates, capped at {cap} lights. Estimate = "
        f"simulated error × {scale:g}. Measured: mean angle to the scene's true normals "
        "(robust PS on the lights used).",
        "",
        "Estimate / measured after k lights (one session per scene):",
        "",
        "| scene | " + " | ".join(f"k = {k}" for k in CHECK) + " | decision (mean) |",
        "|---|" + "---|" * (len(CHECK) + 1),
    ]
    for s in sessions:
        cells = []
        for k in CHECK:
            if k in s["measured"] and k in s["raw"]:
                cells.append(f"{scale * s['raw'][k]:.2f} / {s['measured'][k]:.2f}")
            else:
                cells.append("")
        lines.append(f"| {_name(s)} | " + " | ".join(cells) + f" | {s['decision_s']:.2f} s |")
    lines += [
        "",
        "The stop per target: on the point estimate (format 7), on the point × "
        f"{upper:g} alone (format 8) and as it ships (the larger of the point × {upper:g} and "
        "the images' misfit bound, plus the unsolved share × 90°: "
        "`planner.adaptive_until.upper_error_deg`). Each rule's estimate column is what it "
        "compares with the target. (cap): the session's maximum, the target not claimed; "
        "**above**: a claim whose measured error is above its target.",
        "",
        "| scene | target | point stop: lights | point estimate | measured | measured / point | "
        f"×{upper:g} stop: lights | upper estimate | measured | measured / upper | "
        "shipped stop: lights | upper estimate | measured | measured / upper |",
        "|---|---|" + "---|" * 12,
    ]
    rules = (("point", 1.0, False), ("factor", upper, False), ("shipped", upper, True))
    broken = {name: [0, 0, 0] for name, _, _ in rules}  # claims, claims above target, lights
    for s in sessions:
        for t in targets:
            cells = []
            for name, f, shipped in rules:
                k, u = stop_at(s, t, scale, cap, f, shipped)
                m = s["measured"].get(k, float("nan"))
                claimed = u is not None and u <= t
                broken[name][0] += claimed
                broken[name][1] += claimed and m > t
                broken[name][2] += k
                why = "" if claimed else " (cap)"
                flag = " **above**" if claimed and m > t else ""
                cells.append(
                    f"{k}{why} | {'' if u is None else f'{u:.2f}°'} | {m:.2f}°{flag} | "
                    f"{'' if u is None else f'×{m / u:.2f}'}"
                )
            lines.append(f"| {_name(s)} | {t:g}° | " + " | ".join(cells) + " |")
    said = {"point": "point estimate", "factor": f"×{upper:g} alone", "shipped": "as shipped"}
    lines += [
        "",
        "Claims measured above their target (lights used, summed over the stops): "
        + "; ".join(
            f"{said[n]} {broken[n][1]} of {broken[n][0]} ({broken[n][2]} lights)" for n in said
        )
        + f". Point factor fitted on all scenes (light by light, k ≥ 6): ×{loo['all']:.3f}.",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> str:
    import rti_rig.app.usecases.adaptive as usecase

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="painting,coin,tilted,industrial,tablet")
    ap.add_argument("--cap", type=int, default=60)
    ap.add_argument("--targets", default="1,2,4")
    ap.add_argument("--scale", type=float, default=SIM_ESTIMATE_SCALE)
    ap.add_argument("--greedy", action="store_true", help="format 5's light-by-light choice")
    ap.add_argument(
        "--upper-factor",
        type=float,
        default=UPPER_FACTOR,
        help="the stop's factor on the point estimate (format 8's upper estimate)",
    )
    ap.add_argument("--write", action="store_true", help="write the tables into docs/adaptive.md")
    ap.add_argument("--guesses", default="", help="comma-separated guessed N (to compare)")
    ap.add_argument(
        "--draws", type=int, default=1, help="sessions per scene (draw d > 0: 24 candidates out)"
    )
    ap.add_argument("--seed", type=int, default=0, help="the draws' seed")
    ap.add_argument(
        "--traces",
        type=Path,
        default=None,
        help="write every session's raw estimate and measured error per light count (JSON: "
        "what benchmarks.adaptive_until_bound chooses the stop's upper factor from)",
    )
    ap.add_argument(
        "--clipped-censored",
        action="store_true",
        help="the object model reads observations at white as lower bounds "
        "(planner.adaptive_bias.CLIPPED_CENSORED; off in what ships)",
    )
    ap.add_argument(
        "--first-start",
        action="store_true",
        help="start from the 4 lights of the first guess's homogeneous layout (to compare)",
    )
    args = ap.parse_args(argv)
    if args.first_start:
        import benchmarks.adaptive as bench
        from rti_rig.app.usecases.adaptive import dome_start
        from rti_rig.planner.adaptive_until import GUESSES

        bench.START["start"] = lambda g, k, n, objective="normals": dome_start(
            g, k, GUESSES[0] if n is None else n, objective
        )
    if args.guesses:
        import rti_rig.planner.adaptive_until as until

        until.GUESSES = tuple(int(g) for g in args.guesses.split(","))
    if args.greedy:
        usecase.UNTIL_DESIGN = False
    if args.clipped_censored:
        import rti_rig.planner.adaptive_bias as bias

        bias.CLIPPED_CENSORED = True
    targets = tuple(float(t) for t in args.targets.split(","))
    t0 = time.perf_counter()
    sessions = []
    for scene, draw in ((sc, d) for sc in args.scenes.split(",") for d in range(args.draws)):
        s = session(scene, args.cap, draw, args.seed)
        sessions.append(s)
        if args.traces is not None:  # after each session: a long run keeps what it measured
            save_traces(args.traces, sessions)
        print(
            f"{scene} draw {draw}: {s['seconds']:.0f} s; elevations "
            f"{np.round(s['elev']).astype(int).tolist()}",
            flush=True,
        )
        print(
            "  k: est/measured "
            + ", ".join(
                f"{k}: {args.scale * s['raw'][k]:.2f}/{s['measured'][k]:.2f}"
                for k in sorted(s["measured"])
                if k in s["raw"]
            ),
            flush=True,
        )
    cmd = (
        f"python -m benchmarks.adaptive_until_sim --scenes {args.scenes} --cap {args.cap} "
        f"--targets {args.targets}"
        + (f" --draws {args.draws} --seed {args.seed}" if args.draws > 1 else "")
        + (" --greedy" if args.greedy else "")
        + (" --clipped-censored" if args.clipped_censored else "")
        + (f" --guesses {args.guesses}" if args.guesses else "")
    )
    text = report(
        sessions,
        targets,
        args.scale,
        args.cap,
        cmd,
        time.perf_counter() - t0,
        args.greedy,
        args.upper_factor,
    )
    print(text)
    if args.write:
        write_section("adaptive_until_sim" + ("_greedy" if args.greedy else ""), text, DOC)
    return text


if __name__ == "__main__":
    main()
