"""The `--until-error` stop's upper estimate, chosen leave one scene out on the simulator.

A stop *claims* the target: a user who asks for 2° reads "stopped: ≤ 2°" as a promise. The
point estimate (simulated error × ``SIM_ESTIMATE_SCALE``) is right on average and off by ×0.55–
×2 on single scenes, so about half its claims near the target are broken. This script reads the
traces of ``python -m benchmarks.adaptive_until_sim --draws D --traces FILE`` (every session's
raw estimate and measured error at every light count: a decision does not depend on the target,
so the session stopped at any target is a prefix of the one run to the cap) and, for each rule
and each scene, chooses the rule's factor on the *other* scenes only, then replays the stops of
the left-out scene's sessions at every target. Printed per rule: the claims (stops because the
upper estimate reached the target), how many measure above their target, the lights used, and
measured / upper at the claims.

Rules (``upper_k`` after k lights; ``point_k`` = the shipped point estimate):

* ``point``: the point estimate itself (format 7: factor 1).
* ``q<Q>``: ``F × point_k``, F the Q-quantile of measured / point over every light count
  k ≥ 4 of the other scenes' sessions (all draws).
* ``q<Q>-w<W>``: ``F × max(point_{k-W..k})``: an estimate that has just dropped (a model
  refitted, a design completed) is not trusted until it has stayed down W lights — a term for
  error that no longer falls as fast as the simulated one; F as above, of measured / that max.

* ``<rule>+images``: the rule's factor as above, and the images' terms weighed as the shipped
  stop weighs them (``planner.adaptive_until.upper_error_deg``): the larger of the factor ×
  the point estimate and the misfit bound, plus the unsolved share × ``UNSOLVED_DEG``. The
  shipped stop is ``f1.95+images``; it is always replayed (traces written before the traces
  held the image terms replay it without them, and say so).

Run: ``python -m benchmarks.adaptive_until_bound TRACES.json [--targets ...]``.

The factor was derived on the point estimate alone (the rules without ``+images``), before the
stop weighed the images (2026-12-06): the ``+images`` rows measure what the images' terms add
to it on the calibration's own sessions, not a factor chosen with them.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from rti_rig.planner.adaptive import SIM_ESTIMATE_SCALE
from rti_rig.planner.adaptive_until import UPPER_FACTOR, UPPER_QUANTILE, upper_error_deg

TARGETS = (0.25, 0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0)
QUANTILES = (0.5, 0.75, 0.9, 0.95, 1.0)
WINDOWS = (0, 3, 6)


def load(path: Path, scale: float) -> list[dict]:
    """Sessions with point estimates (scale × raw) and measured errors keyed by int k."""
    rows = json.loads(Path(path).read_text())["sessions"]
    out = []
    for r in rows:
        raw = {int(k): v for k, v in r["raw"].items()}
        meas = {int(k): v for k, v in r["measured"].items()}
        ks = sorted(k for k in raw if k in meas and k >= 4)
        out.append(
            {
                "scene": r["scene"],
                "draw": r["draw"],
                "ks": ks,
                "point": {k: scale * raw[k] for k in ks},
                "measured": meas,
                "cap": max(meas),
                # the stop's image terms (absent from traces written before they were kept)
                "misfit": {int(k): v for k, v in (r.get("misfit") or {}).items()},
                "unsolved": {int(k): v for k, v in (r.get("unsolved") or {}).items()},
            }
        )
    return out


def windowed(s: dict, w: int) -> dict[int, float]:
    """max of the point estimate over the last ``w`` light counts (and this one)."""
    ks = s["ks"]
    return {k: max(s["point"][j] for j in ks if k - w <= j <= k) for k in ks}


def factor(sessions: list[dict], q: float | None, w: int) -> float:
    """The Q-quantile of measured / windowed point over every k of ``sessions`` (None: 1)."""
    if q is None:
        return 1.0
    ratios = [s["measured"][k] / e for s in sessions for k, e in windowed(s, w).items() if e > 0]
    return float(np.quantile(ratios, q))


def stop(s: dict, upper: dict[int, float], target: float) -> tuple[int, bool]:
    """Lights used and whether the stop claimed the target (else the cap)."""
    for k in s["ks"]:
        if upper[k] <= target:
            return k, True
    return s["cap"], False


def evaluate(
    sessions: list[dict],
    q: float | None,
    w: int,
    targets: tuple[float, ...],
    fixed: float | None = None,
    images: bool = False,
) -> dict:
    """The rule's stops on every session at every target, each scene's factor chosen on the
    other scenes (``fixed``: one given factor for all, e.g. the shipped one on fresh draws;
    ``images``: the images' misfit bound and unsolved share weighed as the shipped stop does)."""
    scenes = sorted({s["scene"] for s in sessions})
    per_scene: dict[str, float] = {}
    claims = above = lights = caps = cap_above = 0
    ratios: list[float] = []
    rows = []
    for scene in scenes:
        f = (
            fixed
            if fixed is not None
            else factor([s for s in sessions if s["scene"] != scene], q, w)
        )
        per_scene[scene] = f
        for s in (s for s in sessions if s["scene"] == scene):
            win = windowed(s, w)
            if images:
                upper = {
                    k: upper_error_deg(v, f, s["unsolved"].get(k) or 0.0, None, s["misfit"].get(k))
                    for k, v in win.items()
                }
            else:
                upper = {k: f * v for k, v in win.items()}
            for t in targets:
                k, claimed = stop(s, upper, t)
                m = s["measured"][k]
                lights += k
                if claimed:
                    claims += 1
                    above += m > t
                    ratios.append(m / upper[k])
                else:
                    caps += 1
                    cap_above += m > t
                rows.append((scene, s["draw"], t, k, claimed, upper.get(k), s["point"].get(k), m))
    return {
        "factors": per_scene,
        "all": fixed if fixed is not None else factor(sessions, q, w),
        "claims": claims,
        "above": above,
        "caps": caps,
        "cap_above": cap_above,
        "lights": lights,
        "ratios": ratios,
        "rows": rows,
    }


def name(q: float | None, w: int, fixed: float | None = None, images: bool = False) -> str:
    base = f"f{fixed:g}" if fixed is not None else "point" if q is None else f"q{q:g}"
    return base + (f"-w{w}" if w else "") + ("+images" if images else "")


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("traces", type=Path)
    ap.add_argument("--targets", default=",".join(f"{t:g}" for t in TARGETS))
    ap.add_argument("--scale", type=float, default=SIM_ESTIMATE_SCALE)
    ap.add_argument("--detail", default="", help="a rule whose stops to list, e.g. q0.9")
    ap.add_argument(
        "--fixed",
        default="",
        help="comma-separated factors to replay as given (not chosen: e.g. the factor chosen on "
        "other traces, checked on fresh draws); rules named f<F>",
    )
    args = ap.parse_args(argv)
    targets = tuple(float(t) for t in args.targets.split(","))
    sessions = load(args.traces, args.scale)
    scenes = sorted({s["scene"] for s in sessions})
    draws = len(sessions) // max(1, len(scenes))
    lines = [
        f"Command: `python -m benchmarks.adaptive_until_bound {args.traces.name} --targets "
        f"{args.targets}` ({len(sessions)} sessions: {', '.join(scenes)}; {draws} draws each; "
        f"point estimate = simulated × {args.scale:g}). Each scene's factor chosen on the other "
        "scenes (leave one scene out); stops at every target replayed from the sessions.",
        "",
        "| rule | factor per left-out scene (" + ", ".join(scenes) + ") | factor on all | "
        "claims | claims measured above target | lights used (sum) | measured / upper at "
        "claims (median, max) | cap stops (above target) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    rules: list[tuple[float | None, int, float | None, bool]] = [(None, 0, None, False)]
    rules += [(q, w, None, False) for w in WINDOWS for q in QUANTILES]
    fixed_factors = [float(f) for f in args.fixed.split(",") if f]
    rules += [(None, 0, f, False) for f in fixed_factors]
    # the images' terms: on the quantile the factor was chosen by, and on the shipped factor
    rules += [(UPPER_QUANTILE, 0, None, True)]
    rules += [(None, 0, f, True) for f in dict.fromkeys([*fixed_factors, UPPER_FACTOR])]
    have = sum(bool(s["misfit"]) for s in sessions)
    if have < len(sessions):
        lines[0] += (
            f" {len(sessions) - have} of {len(sessions)} sessions' traces hold no image terms "
            "(written before they were kept): `+images` rows weigh nothing for those."
        )
    results = {}
    for q, w, fixed, images in rules:
        r = evaluate(sessions, q, w, targets, fixed, images)
        label = name(q, w, fixed, images)
        results[label] = r
        rat = np.array(r["ratios"]) if r["ratios"] else np.array([np.nan])
        per = ", ".join(f"{r['factors'][s]:.2f}" for s in scenes)
        lines.append(
            f"| {label} | {per} | "
            f"{r['all']:.2f} | {r['claims']} | {r['above']} "
            f"({100 * r['above'] / max(1, r['claims']):.0f} %) | {r['lights']} | "
            f"×{np.median(rat):.2f}, ×{np.max(rat):.2f} | {r['caps']} ({r['cap_above']}) |"
        )
    if args.detail:
        lines += [
            "",
            f"Stops of `{args.detail}` (left-out factor):",
            "",
            "| scene | draw | target | lights | claimed | upper | point | measured |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for scene, d, t, k, c, up, pt, m in results[args.detail]["rows"]:
            lines.append(
                f"| {scene} | {d} | {t:g}° | {k} | {'yes' if c else 'cap'} | "
                f"{'' if up is None else f'{up:.2f}°'} | {'' if pt is None else f'{pt:.2f}°'} | "
                f"{m:.2f}°{' **above**' if m > t else ''} |"
            )
    text = "\n".join(lines)
    print(text)
    return text


if __name__ == "__main__":
    main()
