"""How far the adaptive chooser's object model renders from the true images, and why.

Why: the relight objective ranks designs by relighting simulated on the model fitted from the
first images (``planner.adaptive_bias.ObjectModel``); where that model renders candidate lights
far from the truth, its ranking of designs is compressed (docs/adaptive.md, "Why the model
rendered a matte tilted plane wrongly"). This script takes one draw of a simulator scene as
``benchmarks.adaptive`` sets it up, runs the chooser to its first decision, and compares the
model's rendering of every candidate light at the sampled pixels with the noise-free simulated
images there, term by term: each of the model's parts (albedo, normals, specular lobe, cast
shadows) is swapped for the truth in turn, and the RMS error left is printed by elevation band.

Run: ``python -m benchmarks.adaptive_render_check [--scenes tilted,tablet,painting]
[--draw D] [--n N]`` (prints only).
"""

from __future__ import annotations

import argparse

import numpy as np

from benchmarks.adaptive import SIM_REMOVED
from benchmarks.tradeoff import TradeoffSettings, render_scene_data, scene_camera
from rti_rig.app.usecases.adaptive import AdaptiveChooser, dome_start
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.adaptive import START_LIGHTS, object_model
from rti_rig.planner.adaptive_bias import _half_cos, _lobe, soft_visibility, visibility

BANDS = ((0, 20), (20, 40), (40, 60), (60, 90))


def _rms(a: np.ndarray) -> float:
    return float(np.sqrt(np.mean(a**2)))


def check(scene_name: str, draw: int, n: int, seed: int = 0) -> None:
    settings = TradeoffSettings(held_out_lights=1, ground_truth_lights=50)
    si = settings.scenes.index(scene_name)
    data = render_scene_data(scene_name, settings)
    scene, shoot = scene_camera(scene_name, settings)
    cand = data.candidate_dirs
    grey = data.candidate_images.mean(axis=-1)
    rng = np.random.default_rng([seed, si])
    for _ in range(draw + 1):
        keep = np.sort(rng.choice(len(cand), len(cand) - SIM_REMOVED, replace=False))
    sub = DomeGeometry(cand[keep], tuple(f"c{i:03d}" for i in keep))
    start = dome_start(sub, START_LIGHTS, n, "relight")
    chooser = AdaptiveChooser(cand[keep], start, n, design_lights=n, objective="relight")
    for i in start[:START_LIGHTS]:
        chooser.observe(i, cand[keep][i], grey[keep][i])
    state = chooser.state()
    model = object_model(state)
    assert model is not None and state.rows is not None
    rows, cols = state.rows, state.cols
    lights = cand[keep]
    el = np.degrees(np.arcsin(lights[:, 2]))
    pix = np.arange(len(rows))

    # the truth at the sampled pixels: noise-free grey images, and their parts
    full = np.stack([shoot(d, None).mean(-1)[rows, cols] for d in lights])  # (L, P)
    lamb = np.stack([shoot(d, None, passes=()).mean(-1)[rows, cols] for d in lights])
    tn = scene.normals[rows, cols]
    talb_raw = scene.albedo.mean(-1)[rows, cols]
    cos_t = np.maximum(tn @ lights.T, 0).T
    k = float(np.median((lamb / np.maximum(talb_raw[None] * cos_t, 1e-9))[cos_t > 0.3]))
    talb = k * talb_raw
    with np.errstate(invalid="ignore", divide="ignore"):
        tvis = np.where(lamb > 1e-6, full / np.maximum(lamb, 1e-12), 1.0)

    mvis = visibility(model, lights, pix).T  # (L, P)
    mcos = (model.normals @ lights.T).T
    mlobe = np.zeros_like(mcos)
    if model.spec_strength > 0:
        mlobe = model.spec_strength * _lobe(_half_cos(model.normals, lights), model.spec_exponent).T
        mlobe = mlobe * (mcos > 0)

    def rend(n_, a_, vis_, lobe_=True) -> np.ndarray:
        c = (n_ @ lights.T).T
        out = a_[None] * np.maximum(c, 0)
        if lobe_:
            out = out + mlobe
        return out * vis_

    ang = np.degrees(np.arccos(np.clip((model.normals * tn).sum(1), -1, 1)))
    print(
        f"\n== {scene_name} draw {draw} N={n}: {len(rows)} sampled pixels, "
        f"{len(lights)} candidates; exposure factor {k:.3f}"
    )
    ratio = model.albedo / talb
    print(
        f"   normals: mean {ang.mean():.2f}°, median {np.median(ang):.2f}°; albedo model/true "
        f"median {np.median(ratio):.3f} (IQR "
        f"{np.percentile(ratio, 25):.3f}–{np.percentile(ratio, 75):.3f})"
    )
    print(
        f"   lobe: ks {model.spec_strength:.4f} e {model.spec_exponent:g}; "
        f"noise {model.noise:.4f} (variance {model.noise_var0 or 0:.3g} + "
        f"{model.noise_slope:.3g} × signal);"
        f" captured-shadow fraction {model.shadowed.mean():.3f}; relief "
        f"{'none' if model.relief is None else 'yes'}"
    )
    if model.relief is not None:
        h = model.relief[0]
        th = scene.height - scene.height.mean()
        hh = h - h.mean()
        print(
            f"   relief: model height range {np.ptp(hh):.1f} px, true {np.ptp(th):.1f} px; "
            f"RMS diff {_rms(hh - th):.2f} px"
        )
        # the model's relief swapped for the true height: its march alone
        tvis_march = soft_visibility(np.asarray(scene.height), rows, cols, lights).T
    else:
        tvis_march = np.ones_like(tvis)
    variants = {
        "model": rend(model.normals, model.albedo, mvis),
        "no lobe": rend(model.normals, model.albedo, mvis, lobe_=False),
        "true albedo": rend(model.normals, talb, mvis),
        "true normals": rend(tn, model.albedo, mvis),
        "true vis": rend(model.normals, model.albedo, tvis),
        "no vis (1)": rend(model.normals, model.albedo, np.ones_like(mvis)),
        "march true h": rend(model.normals, model.albedo, tvis_march),
        "true n+a, m.vis": rend(tn, talb, mvis, lobe_=False),
        "true n+a+vis": rend(tn, talb, tvis, lobe_=False),
    }
    head = "   variant           all   " + "  ".join(f"el{a:02d}-{b:02d}" for a, b in BANDS)
    val = state.valid
    print(
        f"   valid (solved) pixels {val.mean():.3f}; normal error on valid "
        f"{ang[val].mean():.2f}° (median {np.median(ang[val]):.2f}°), on unsolved "
        f"{ang[~val].mean() if (~val).any() else float('nan'):.2f}°"
    )
    for name in ("model", "true normals"):
        e = variants[name] - full
        print(
            f"   {name}: RMS on valid {_rms(e[:, val]):.4f}, on unsolved "
            f"{_rms(e[:, ~val]) if (~val).any() else float('nan'):.4f}"
        )
    print(head)
    for name, r in variants.items():
        e = r - full
        cells = []
        for a, b in BANDS:
            m = (el >= a) & (el < b)
            cells.append(f"{_rms(e[m]):.4f} " if m.any() else "   -    ")
        print(f"   {name:16s} {_rms(e):.4f}  " + "  ".join(cells))
    mean_level = {f"{a}-{b}": float(full[(el >= a) & (el < b)].mean()) for a, b in BANDS}
    print("   mean true level by band:", {k_: round(v, 3) for k_, v in mean_level.items()})
    # visibility disagreement
    shadow_t = tvis < 0.5
    shadow_m = mvis < 0.5
    print(
        f"   cast-shadow fraction true {shadow_t.mean():.3f}, model {shadow_m.mean():.3f}, "
        f"both {(shadow_t & shadow_m).mean():.3f}; march over true h "
        f"{(tvis_march < 0.5).mean():.3f}"
    )
    face = (tn @ lights.T).T > 0.15
    print(
        f"   where the light faces the pixel (true n.l > 0.15, {face.mean():.3f} of all): "
        f"shadowed (vis < 0.5) true {(shadow_t & face).sum() / face.sum():.3f}, model "
        f"{(shadow_m & face).sum() / face.sum():.3f}, march over true h "
        f"{((tvis_march < 0.5) & face).sum() / face.sum():.3f}; partly lit (0.05 < vis < 0.95)"
        f" true {((tvis > 0.05) & (tvis < 0.95) & face).sum() / face.sum():.3f}, model "
        f"{((mvis > 0.05) & (mvis < 0.95) & face).sum() / face.sum():.3f}"
    )
    print(
        f"   mean vis where facing: true {tvis[face].mean():.3f}, model {mvis[face].mean():.3f},"
        f" march over true h {tvis_march[face].mean():.3f}"
    )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", default="tilted,tablet,painting")
    ap.add_argument("--draw", type=int, default=0)
    ap.add_argument("--n", type=int, default=6)
    a = ap.parse_args()
    for s in a.scenes.split(","):
        check(s, a.draw, a.n)


if __name__ == "__main__":
    main()
