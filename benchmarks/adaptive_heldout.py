"""Object-model variants judged on held-out captured images: does that rank designs better?

Why: docs/adaptive.md ("The fitted surface or the objective?") ends on one idea not tried: an
object model whose errors a search cannot exploit, scored on *held-out captured images* rather
than on its own renderings. This probe measures it at the first decision (the shipped start,
4 images; the benchmark's draws, as ``benchmarks.adaptive_reach``):

* **variants** of the object model the chooser fits (``planner.adaptive.object_model``):
  ``fitted`` (as it ships), ``no-shadow`` (no cast shadows: neither the captured horizons nor
  the relief), ``relief2`` (the relief's detail ×2), ``glossy`` (the lobe ×2, at least 5 % of
  the median albedo), ``matte`` (no lobe), ``smooth`` (normals and albedo averaged over the
  ``SMOOTH_K`` nearest sampled pixels in the image);
* **held-out evidence** per variant: each captured image left out in turn, the normals and
  albedo solved by least squares from the others (``adaptive_bias.solve_unsolved``), the
  held-out image predicted by the variant at its recorded light (its captured shadow under that
  light dropped), and the prediction error in the model's noise units, robustly (the mean of
  ``log(1 + (z / 3)²)``). The variant's global parts (lobe, relief, the other lights' shadows)
  come from the model fitted on every image: with 4 images a fit on 3 has no residual to see a
  lobe in (a small leak: 2 global numbers and the relief);
* **criteria** ranking the designs the chooser offers (the floors' completions and the fitted
  design): ``shipped`` (the simulated robust fit on ``fitted``), ``select`` (on the variant
  the held-out images favour), ``1se`` (the mean over the variants within one standard error —
  across held-out images, paired — of the favoured one), ``mean`` (over every variant),
  ``minimax`` (the worst variant); and, benchmark-only, ``truth-pred`` (on the variant whose
  renderings best predict the *true* images of every light not shot: what a perfect selector
  of variants by prediction would use — does predicting better rank designs better?), and
  ``bar-regret`` (2026-11-30, issue 28): per variant also the four *full* homogeneous layouts
  of N (floors 0/10/20/30, not completions of the lights shot: the bar as that variant sees
  it) are simulated, and a design scores ``max_v simerr_v(d) / min_f simerr_v(H_f)``, its
  worst predicted loss against the bar (:func:`bar_regret`);
* each criterion's design taken as the chooser takes it (the default floor kept unless another
  is 10 % better, ``planner.adaptive._switch``), its true error, and the **rank correlation**
  (Spearman, and the regret of the criterion's best design) of the criterion's scores with the
  designs' true errors, per decision.

``--all-decisions``: instead, at every decision of the shipped chooser's sessions, each
criterion's rank correlation and regret over the designs offered (the session follows what
ships).

``python -m benchmarks.adaptive --heldout-score select|1se|mean|minimax`` runs the chooser
itself with its designs scored so (:func:`install`), every decision.

Run: ``python -m benchmarks.adaptive_heldout [--draws K] [--scenes a,b] [--ns 6,9] [--seed S]
[--all-decisions]`` (all scenes and N, 8 draws: about 11 min on 2 loaded cores with
``bar-regret``'s layouts, 3–9 min before;
``--all-decisions`` on 3 scenes at 6 and 9 lights about 5 min). Prints a table per cell and
the mean rank correlations; writes nothing.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree
from scipy.stats import spearmanr

from benchmarks.adaptive_reach import (
    FLOORS,
    _draw_lights,
    _floor_completions,
    _layout_error,
    _scenes,
    _score_floors,
    _start_state,
)
from rti_rig.app.usecases.adaptive import dome_start, robust_fit, sample_pixels
from rti_rig.planner import adaptive
from rti_rig.planner import adaptive_optimal as ao
from rti_rig.planner.adaptive import object_model
from rti_rig.planner.adaptive_bias import (
    ObjectModel,
    _render,
    simulate_designs,
    solve_unsolved,
)

VARIANTS = ("fitted", "no-shadow", "relief2", "glossy", "matte", "smooth")
CRITERIA = ("shipped", "select", "1se", "mean", "minimax")
#: and, in the first-decision probe only, ``truth-pred``: the variant that best predicts the
#: *true* images of every light not shot (a perfect variant selector; benchmark-only), and
#: ``bar-regret``: the worst, over the variants, of a design's simulated error over the best of
#: that variant's own *full* homogeneous layouts (:func:`bar_regret`)
PROBE_CRITERIA = (*CRITERIA, "truth-pred", "bar-regret")
#: neighbours a ``smooth`` normal is averaged over (sampled pixels, image distance)
SMOOTH_K = 16
#: the robust loss's scale, noise units
LOSS_C = 3.0


def _fresh(model: ObjectModel, **kw) -> ObjectModel:  # type: ignore[no-untyped-def]
    """``model`` with fields replaced and an empty rendering cache (replace would share it)."""
    return dataclasses.replace(model, rendered={}, **kw)


def _smooth_field(model: ObjectModel, rho_n: NDArray, ok: NDArray) -> tuple[NDArray, NDArray]:
    """(normals, albedo): each pixel's ``rho n`` averaged over its nearest solved pixels."""
    assert model.relief is not None
    _, rows, cols = model.relief
    xy = np.c_[rows, cols].astype(np.float64)
    tree = cKDTree(xy[ok])
    k = min(SMOOTH_K, int(ok.sum()))
    _, idx = tree.query(xy, k=k)
    idx = np.atleast_2d(idx.T).T if k > 1 else idx[:, None]
    b = rho_n[ok][idx].mean(axis=1)
    rho = np.linalg.norm(b, axis=1)
    return b / np.maximum(rho, 1e-12)[:, None], rho


def variants(model: ObjectModel) -> dict[str, ObjectModel]:
    out = {"fitted": model}
    out["no-shadow"] = _fresh(model, relief=None, shadow_el=np.full_like(model.shadow_el, -np.inf))
    if model.relief is not None:
        h, r, c = model.relief
        out["relief2"] = _fresh(model, relief=(2.0 * h, r, c))
    ks = max(2.0 * model.spec_strength, 0.05 * float(np.median(model.albedo)))
    out["glossy"] = _fresh(model, spec_strength=ks)
    out["matte"] = _fresh(model, spec_strength=0.0)
    if model.relief is not None:
        n, rho = _smooth_field(
            model, model.normals * model.albedo[:, None], np.ones(len(model.albedo), bool)
        )
        out["smooth"] = _fresh(model, normals=n, albedo=rho)
    return out


def heldout_losses(state, model: ObjectModel, vs: dict[str, ObjectModel]) -> dict[str, NDArray]:  # type: ignore[no-untyped-def]
    """Per variant: the robust held-out loss of each captured image (K,)."""
    obs = np.asarray(state.obs, dtype=np.float64)
    lights = state.lights
    k_all = len(lights)
    p = obs.shape[1]
    out: dict[str, list[float]] = {v: [] for v in vs}
    for k in range(k_all):
        rest = np.r_[0:k, k + 1 : k_all]
        n0 = np.tile([0.0, 0.0, 1.0], (p, 1))
        n, a, solved, _ = solve_unsolved(
            obs[rest], lights[rest], n0, np.zeros(p), np.zeros(p, bool), state.dark
        )
        if solved.sum() < 10:
            continue
        pix = np.flatnonzero(solved)
        for name, v in vs.items():
            if name == "smooth":
                sn, sa = _smooth_field(model, n * a[:, None], solved)
                nn, aa = sn, sa
            else:
                nn, aa = n, a
            sel = v.shadow_el.copy()
            sel[:, k] = -np.inf  # the held-out image's own shadows are not evidence
            vk = _fresh(v, normals=nn, albedo=aa, shadow_el=sel)
            pred = _render(vk, lights[k : k + 1], pix)[0]
            sd = np.asarray(model.noise_sd(pred), dtype=np.float64) + 0.0 * pred
            z = (obs[k, pix] - pred) / np.maximum(sd, 1e-9)
            out[name].append(float(np.mean(np.log1p((z / LOSS_C) ** 2))))
    return {name: np.array(x) for name, x in out.items()}


def truly_predicting(
    dirs: NDArray, model: ObjectModel, vs: dict[str, ObjectModel], truth: NDArray, shot: list[int]
) -> str:
    """The variant whose renderings best predict the *true* sampled observations ``truth``
    (L, P) of every light (``dirs`` (L, 3)) not ``shot`` (the same robust loss in the model's
    noise units as :func:`heldout_losses`): what a perfect selector of variants by prediction
    would pick."""
    rest = np.setdiff1d(np.arange(len(truth)), shot)
    dirs = np.asarray(dirs)[rest]
    pix = np.arange(len(model.normals))
    truth = truth[:, sample_columns(model, truth.shape[1])]
    best, name = np.inf, "fitted"
    for v, m in vs.items():
        pred = _render(_fresh(m), dirs, pix)  # (L', P)
        sd = np.asarray(model.noise_sd(pred), dtype=np.float64) + 0.0 * pred
        z = (truth[rest] - pred) / np.maximum(sd, 1e-9)
        loss = float(np.mean(np.log1p((z / LOSS_C) ** 2)))
        if loss < best:
            best, name = loss, v
    return name


def sample_columns(model: ObjectModel, samples: int) -> NDArray[np.intp]:
    """The columns of the chooser's pixel sample (``sample_pixels``, ``samples`` of them) that
    the model's pixels are: the state keeps only the pixels not dark under every light shot."""
    from rti_rig.app.usecases.adaptive import sample_index

    assert model.relief is not None
    height, rows, cols = model.relief
    h, w = height.shape
    flat = sample_index(h * w)
    assert flat.size == samples
    where = {int(f): j for j, f in enumerate(flat)}
    return np.array([where[int(r) * w + int(c)] for r, c in zip(rows, cols, strict=True)])


def criteria_scores(
    sims: dict[str, list[float]], losses: dict[str, NDArray]
) -> tuple[dict[str, list[float]], str]:
    """Per criterion, the designs' scores; and the variant the held-out images favour."""
    names = [v for v in sims if losses.get(v, np.zeros(0)).size]
    mean_loss = {v: float(losses[v].mean()) for v in names}
    best = min(names, key=lambda v: mean_loss[v]) if names else "fitted"
    plausible = [best]
    if names and losses[best].size > 1:
        for v in names:
            d = losses[v] - losses[best]
            se = float(d.std(ddof=1) / np.sqrt(d.size)) if d.size > 1 else 0.0
            if v != best and d.mean() <= se:
                plausible.append(v)
    arr = {v: np.array(s) for v, s in sims.items()}
    allv = np.array(list(arr.values()))
    return {
        "shipped": list(arr["fitted"]),
        "select": list(arr[best]),
        "1se": list(np.mean([arr[v] for v in plausible], axis=0)),
        "mean": list(allv.mean(axis=0)),
        "minimax": list(allv.max(axis=0)),
    }, best


def full_homogeneous(dirs: NDArray, n: int) -> list[NDArray]:
    """The full homogeneous layouts of ``n`` of the candidates ``dirs`` (K, 3), one per shipped
    floor (:data:`FLOORS`; a floor with too few candidates left out), as light sets (n, 3): the
    bar's layouts, not completions of the lights shot (``homogeneous_completion`` with none
    used, which matches the ideal layout to the candidates as ``select_uniform_leds`` does)."""
    free = np.ones(len(dirs), dtype=bool)
    out = []
    for f in FLOORS:
        idx = adaptive.homogeneous_completion(dirs, free, np.zeros((0, 3)), n, f)
        if idx is not None and idx.size == n:
            out.append(np.asarray(dirs)[idx])
    return out


def bar_regret(sims: dict[str, list[float]], bars: dict[str, list[float]]) -> list[float]:
    """Per design: ``max_v sims[v][d] / min(bars[v])``, the worst over the variants of the
    design's simulated error relative to the best homogeneous layout *as that variant sees it*.

    Why: raw ``minimax`` is ruled by the hardest variant (its errors are the largest whatever
    the design); dividing by each variant's own bar removes its overall difficulty and scores
    the design by its worst predicted loss against the bar the issue sets (the hindsight-tuned
    homogeneous layout). Below 1: every variant predicts the design beats its best layout."""
    ratio = [np.asarray(sims[v], dtype=np.float64) / max(min(bars[v]), 1e-12) for v in sims]
    return [float(x) for x in np.max(ratio, axis=0)]


def probe(draws: int, scenes: tuple[str, ...], ns: tuple[int, ...], seed: int = 0) -> str:
    rows = []
    rho_all: dict[str, list[float]] = {c: [] for c in PROBE_CRITERIA}
    cells_of: list = []  # type: ignore[type-arg]
    for _, scene, data, rng in _scenes(scenes, seed):
        cand = data.candidate_dirs
        grey = data.candidate_images.mean(axis=-1)
        err = _layout_error(data)
        res: dict[tuple[int, str], list[float]] = {}
        favoured: dict[int, list[str]] = {}
        rho: dict[tuple[int, str], list[float]] = {}
        for _ in range(draws):
            keep, sub = _draw_lights(rng, len(cand), cand)
            g_sample = sample_pixels(grey[keep]).astype(np.float64)  # (L, P): every light
            for n in adaptive_ns(ns):
                _score_floors(res, n, keep, sub, err)
            for n in ns:
                st = np.asarray(dome_start(sub, adaptive.START_LIGHTS, n))
                _, comps = _floor_completions(cand[keep], st, n)
                state = _start_state(cand[keep], grey[keep], list(st), n)
                model = object_model(state)
                assert model is not None
                fitted = ao.pinned_optimal_design(state, cand[keep], st, comps)
                keys = [*FLOORS, adaptive.FITTED_KEY]
                designs = [*comps, fitted]
                lights = [np.concatenate([cand[keep][st], cand[keep][c]]) for c in designs]
                true = [err(keep[np.r_[st, c]]) for c in designs]
                vs = variants(model)
                sims = {v: simulate_designs(m, lights, robust_fit) for v, m in vs.items()}
                losses = heldout_losses(state, model, vs)
                crit, best_v = criteria_scores(sims, losses)
                truly = truly_predicting(cand[keep], model, vs, g_sample, list(st))
                crit["truth-pred"] = sims[truly]
                homs = full_homogeneous(cand[keep], n)
                bars = {v: simulate_designs(m, homs, robust_fit) for v, m in vs.items()}
                crit["bar-regret"] = bar_regret(sims, bars)
                favoured.setdefault(n, []).append(best_v)
                favoured.setdefault(-n, []).append(truly)
                res.setdefault((n, "best design"), []).append(min(true))
                for v in vs:
                    pick = adaptive._switch(dict(zip(keys, sims[v], strict=True)), 10.0, 0.1, None)
                    res.setdefault((n, f"v {v}"), []).append(true[keys.index(pick)])
                    r = spearmanr(sims[v], true).statistic
                    rho_all.setdefault(f"variant {v}", []).append(
                        0.0 if not np.isfinite(r) else float(r)
                    )
                for c, s in crit.items():
                    pick = adaptive._switch(dict(zip(keys, s, strict=True)), 10.0, 0.1, None)
                    res.setdefault((n, c), []).append(true[keys.index(pick)])
                    r = spearmanr(s, true).statistic
                    r = 0.0 if not np.isfinite(r) else float(r)
                    rho.setdefault((n, c), []).append(r)
                    rho_all[c].append(r)
                    res.setdefault((n, f"regret {c}"), []).append(
                        true[int(np.argmin(s))] / min(true) - 1.0
                    )
        cells_of.append((scene, res))
        tuned = min(
            FLOORS,
            key=lambda f: np.mean([np.mean(res[(m, f"hom {f:g}")]) for m in adaptive_ns(ns)]),
        )
        for n in ns:
            bar = float(np.mean(res[(n, f"hom {tuned:g}")]))

            def cell(label: str, n=n, bar=bar, res=res) -> str:  # type: ignore[no-untyped-def]
                v = float(np.mean(res[(n, label)]))
                return f"{v:.3g}" + ("*" if v > bar * (1 + 1e-9) else "")

            crit_cells = [
                f"{cell(c)} (ρ {np.mean(rho[(n, c)]):+.2f}, regret "
                f"{np.mean(res[(n, f'regret {c}')]):.2f})"
                for c in PROBE_CRITERIA
            ]
            fav = "; ".join(
                ",".join(f"{v}:{favoured[m].count(v)}" for v in VARIANTS if v in favoured[m])
                for m in (n, -n)
            )
            rows.append(
                f"| {scene} | {n} | {tuned:g}°: {bar:.3g} | {cell('best design')} | "
                + " | ".join(crit_cells)
                + " | "
                + " ".join(f"{v} {cell('v ' + v)}" for v in VARIANTS if (n, f"v {v}") in res)
                + f" | {fav} |"
            )
        print(f"{scene} done", flush=True)
    head = (
        "| scene | N | bar | best design | "
        + " | ".join(PROBE_CRITERIA)
        + " | per variant (its own score) | favoured (held-out; truly best-predicting) |\n|"
        + "---|" * (6 + len(PROBE_CRITERIA))
    )
    summary = ", ".join(f"{c} {np.mean(v):+.3f}" for c, v in rho_all.items())
    excess = []
    for label in [*PROBE_CRITERIA, *(f"v {v}" for v in VARIANTS)]:
        total, above = 0.0, []
        for scene, res in cells_of:
            tuned = min(
                FLOORS,
                key=lambda f, res=res: np.mean(
                    [np.mean(res[(m, f"hom {f:g}")]) for m in adaptive_ns(ns)]
                ),
            )
            for n in ns:
                if (n, label) not in res:
                    continue
                bar = float(np.mean(res[(n, f"hom {tuned:g}")]))
                v = float(np.mean(res[(n, label)]))
                total += max(0.0, v / bar - 1.0)
                if v > bar * (1 + 1e-9):
                    above.append(f"{scene} {n}")
        excess.append(f"{label}: Σ {total:.3f}, above the bar in {len(above)} ({', '.join(above)})")
    return (
        f"{head}\n"
        + "\n".join(rows)
        + f"\n\nmean Spearman ρ (criterion score vs true error, per decision): {summary}"
        + "\n(* above the bar; regret: the criterion's best design's true error over the "
        "best's, −1)"
        + "\n\nΣ relative excess over the bar of the design taken at the first decision (with the "
        "chooser's 10 % margin from the default floor), and the cells above the bar (means, "
        "not paired verdicts):\n" + "\n".join(f"* {x}" for x in excess)
    )


def decisions_probe(draws: int, scenes: tuple[str, ...], ns: tuple[int, ...], seed: int = 0) -> str:
    """At *every* decision of the shipped chooser's sessions (not only the first): each
    criterion's rank correlation with the designs' true errors and the regret of its best
    design. The session follows what ships; the criteria only rank the designs it was offered
    (the floors' completions of the lights shot so far and the fitted design)."""
    from rti_rig.app.usecases.adaptive import AdaptiveChooser

    rows = []
    pooled: dict[str, list[float]] = {}
    for _, scene, data, rng in _scenes(scenes, seed):
        cand = data.candidate_dirs
        grey = data.candidate_images.mean(axis=-1)
        err = _layout_error(data)
        got: dict[tuple[int, str], list[float]] = {}
        for _ in range(draws):
            keep, sub = _draw_lights(rng, len(cand), cand)
            dirs, g = cand[keep], grey[keep]
            for n in ns:
                st = list(dome_start(sub, adaptive.START_LIGHTS, n))
                chooser = AdaptiveChooser(dirs, st, n, None, design_lights=n)
                shot: list[int] = []
                for i in range(n):
                    if i >= adaptive.START_LIGHTS:
                        state = chooser.state()
                        model = object_model(state)
                        assert model is not None
                        _, comps = _floor_completions(dirs, shot, n)
                        comps = [c for c in comps if c is not None and c.size]
                        fitted = ao.pinned_optimal_design(state, dirs, np.asarray(shot), comps)
                        designs = [*comps, fitted]
                        lights = [np.concatenate([dirs[shot], dirs[c]]) for c in designs]
                        true = [err(keep[np.r_[shot, c]]) for c in designs]
                        vs = variants(model)
                        sims = {v: simulate_designs(m, lights, robust_fit) for v, m in vs.items()}
                        crit, _ = criteria_scores(sims, heldout_losses(state, model, vs))
                        crit.update({f"variant {v}": s for v, s in sims.items()})
                        for c, sc in crit.items():
                            r = spearmanr(sc, true).statistic
                            r = 0.0 if not np.isfinite(r) else float(r)
                            got.setdefault((n, c), []).append(r)
                            got.setdefault((n, f"regret {c}"), []).append(
                                true[int(np.argmin(sc))] / min(true) - 1.0
                            )
                            pooled.setdefault(c, []).append(r)
                    c, _ = chooser.decide(i)
                    assert c is not None
                    chooser.observe(c, dirs[c], g[c])
                    shot.append(int(c))
        for n in ns:
            cells = [
                f"{np.mean(got[(n, c)]):+.2f} / {np.mean(got[(n, f'regret {c}')]):.2f}"
                for c in CRITERIA
            ]
            rows.append(
                f"| {scene} | {n} | {len(got[(n, 'shipped')])} | " + " | ".join(cells) + " |"
            )
        print(f"{scene} done", flush=True)
    head = (
        "| scene | N | decisions | " + " | ".join(CRITERIA) + " |\n|" + "---|" * (3 + len(CRITERIA))
    )
    summary = ", ".join(f"{c} {np.mean(v):+.3f}" for c, v in pooled.items())
    return (
        "Every decision of the shipped chooser's sessions: mean Spearman ρ of each criterion's "
        "design scores with the designs' true errors / mean regret of its best design\n\n"
        f"{head}\n" + "\n".join(rows) + f"\n\nmean ρ over every decision: {summary}"
    )


def install(criterion: str) -> None:
    """Make the chooser (``planner.adaptive.choose_in_design``, normals objective) score its
    designs by ``criterion`` (one of :data:`CRITERIA` but ``shipped``, or ``variant-NAME``: one
    variant of :data:`VARIANTS`, without held-out evidence) instead of the simulated
    robust fit on the object model as fitted: ``benchmarks.adaptive --heldout-score``. The
    state each decision's model is fitted from is kept (the held-out losses need its images).
    A benchmark's monkeypatch, not a planner change."""
    fixed = criterion.removeprefix("variant-")
    if criterion not in CRITERIA[1:] and not (criterion != fixed and fixed in VARIANTS):
        choices = [*CRITERIA[1:], *(f"variant-{v}" for v in VARIANTS[1:])]
        raise SystemExit(f"--heldout-score: one of {', '.join(choices)}")
    import rti_rig.planner.adaptive as planner

    last: list = []  # type: ignore[type-arg]
    fit_model = planner.object_model

    def object_model_kept(state):  # type: ignore[no-untyped-def]
        last[:] = [state]
        return fit_model(state)

    def scored(model, designs, fit, *a, **kw):  # type: ignore[no-untyped-def]
        if criterion != fixed:  # one variant, no held-out evidence
            return simulate_designs(variants(model)[fixed], designs, fit, *a, **kw)
        state = last[0]
        vs = variants(model)
        sims = {v: simulate_designs(m, designs, fit, *a, **kw) for v, m in vs.items()}
        losses = heldout_losses(state, model, vs)
        crit, _ = criteria_scores(sims, losses)
        return [float(x) for x in crit[criterion]]

    planner.object_model = object_model_kept
    planner.simulate_designs = scored


def adaptive_ns(ns: tuple[int, ...]) -> tuple[int, ...]:
    """The N the bar is tuned over: every N of the benchmark (the bar's floor is per scene)."""
    from benchmarks.adaptive_reach import NS

    return NS


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--draws", type=int, default=8)
    ap.add_argument("--scenes", default="")
    ap.add_argument("--ns", default="6,9,12,18")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--all-decisions",
        action="store_true",
        help="instead: the rank correlations at every decision of the shipped chooser's sessions",
    )
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    fn = decisions_probe if args.all_decisions else probe
    md = fn(
        args.draws,
        tuple(x for x in args.scenes.split(",") if x),
        tuple(int(x) for x in args.ns.split(",")),
        args.seed,
    )
    md += f"\n\n({time.perf_counter() - t0:.0f} s)"
    print(md)
    return md


if __name__ == "__main__":
    main(sys.argv[1:])
