"""The speed/accuracy benchmark: how much each light (and each minute) buys, per planner.

The paper's protocol on the simulator: for each scene, a dense homogeneous acquisition is the
ground truth (true normals, plus noise-free images under held-out lights for relighting). A
dense virtual dome offers the candidate lights. Each planner chooses N of them from one preview
shot; the chosen images (rendered with shadows, specular and sensor noise) are fitted, and the
result is scored against the ground truth:

* normals: robust photometric stereo → mean angular error over *every* pixel (a pixel the fit
  cannot solve counts with the default normal, so a plan that leaves pixels unsolved is not
  flattered);
* relighting: the model chosen from the acquired images alone ("model only what the scene
  requires", by held-out error) → PSNR and SSIM on held-out ground-truth lights.

Each plan is also timed as a session on the simulated dome (constant time per light) and on the
simulated arm (move time depends on the order and the distances), so error can be read against
session time. This module composes simulator, planner and reconstruction, so it sits beside the
composition root and is only imported by the CLI.
"""

from __future__ import annotations

import csv
import time
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.clock import VirtualClock
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry

if TYPE_CHECKING:
    from rti_rig.app.config import LoadedRig

FULL_COUNTS = (3, 4, 5, 6, 8, 10, 12, 16, 20, 30, 50, 100)
QUICK_COUNTS = (3, 6, 12, 30)
FLOORS_DEG = (0.0, 10.0, 20.0, 30.0, 40.0)


@dataclass(frozen=True)
class TradeoffSettings:
    """What the benchmark runs; ``quick()`` is a smaller version for CI-sized machines."""

    scenes: tuple[str, ...] = ("painting", "coin", "tilted", "industrial", "tablet")
    size_px: int = 96
    counts: tuple[int, ...] = FULL_COUNTS
    ground_truth_lights: int = 500
    held_out_lights: int = 40
    candidates: int = 240
    preview_light_az_el_deg: tuple[float, float] = (45.0, 50.0)
    floors_deg: tuple[float, ...] = FLOORS_DEG
    seed: int = 0
    methods: tuple[tuple[str, str], ...] = (
        ("uniform", "normals"),
        ("kmeans", "normals"),
        ("optimal", "normals"),
        ("optimal", "relight"),
    )

    @classmethod
    def quick(cls) -> TradeoffSettings:
        return cls(
            scenes=("painting", "coin", "tilted", "industrial"),
            size_px=48,
            counts=QUICK_COUNTS,
            ground_truth_lights=150,
            held_out_lights=20,
            candidates=120,
        )


@dataclass
class Row:
    """One (scene, plan, N) result."""

    scene: str
    method: str
    objective: str
    n: int
    floor_deg: float
    normal_mean_deg: float
    normal_median_deg: float
    normal_valid_fraction: float
    relight_model: str
    relight_psnr_db: float
    relight_ssim: float
    dome_time_s: float
    arm_time_s: float
    plan_s: float
    #: relighting of the fit.rti `rti-rig fit --model auto` would write for this layout (its
    #: HSH order, chosen on the layout's own images) on the same held-out lights
    #: (``benchmarks.tradeoff_from``; empty / NaN where not measured)
    file_model: str = ""
    file_psnr_db: float = float("nan")
    #: the plan's lights, their candidate indices in the order chosen, space-separated: what
    #: :func:`retime_arm` checks a plan made again against (a planner changed since the run
    #: chooses other lights for the same row, whose scores are not the new plan's); in
    #: ``benchmarks.tradeoff_from``'s rows, the acquisition's lights by their number in its
    #: ``.lp`` (from 1, as a refusal numbers them), in the order chosen
    lights: str = ""


@dataclass
class SceneData:
    """Everything rendered once per scene and shared by every plan."""

    name: str
    normals: NDArray[np.float64]
    candidate_dirs: NDArray[np.float64]
    candidate_images: NDArray[np.float32]  # (M, H, W, 3) noisy, in units of the white level
    held_dirs: NDArray[np.float64]
    held_images: NDArray[np.float32]  # noise-free, same units
    preview: NDArray[np.float32]
    passes: tuple[str, ...] = field(default_factory=tuple)
    material: str = ""  # the scene's own description of its surface


def scene_camera(
    name: str, s: TradeoffSettings, passes: Iterable[str] | None = None
) -> tuple[Any, Callable[..., NDArray[np.float32]]]:
    """The benchmark's scene and a ``shoot(direction, rng)`` in units of the white level.

    ``rng=None`` gives the noise-free image; ``passes`` overrides the scene's render passes
    (``benchmarks.planner_sim_losses`` renders one physical effect at a time); ``irradiance``
    scales the light before the camera exposes, so a brighter LED saturates as it would
    (``benchmarks.planner_sim_jpeg``'s LED spread).
    """
    from rti_rig.simulator.camera_model import CameraModel
    from rti_rig.simulator.light_transport import DirectionalLight, render_radiance
    from rti_rig.simulator.scenes import make_scene

    scene = make_scene(name, s.size_px, s.size_px, seed=s.seed)
    camera = CameraModel()
    # Exposure: a white Lambertian patch facing the light at 80 % of white (as a user meters).
    exposure = camera.exposure_for(1.0, 0.8)
    white = float(camera.white_level)

    def shoot(
        direction: NDArray[np.float64],
        rng: np.random.Generator | None,
        passes: Iterable[str] | None = passes,
        irradiance: float = 1.0,
    ) -> NDArray[np.float32]:
        light = DirectionalLight(tuple(direction), irradiance)
        radiance = render_radiance(scene, light, passes)
        if rng is None:
            scale = camera.expected_electrons(radiance, exposure) * camera.dn_per_electron
            return np.clip(scale / white, 0.0, 1.0).astype(np.float32)
        pixels, wl = camera.expose(radiance, exposure, rng)
        return (pixels.astype(np.float32) / wl).astype(np.float32)

    return scene, shoot


def render_scene_data(
    name: str, s: TradeoffSettings, candidate_irradiance: ArrayLike | None = None
) -> SceneData:
    """Render the candidate lights (with noise) and the held-out reference (noise-free).

    ``candidate_irradiance`` (one factor per candidate, default 1) scales each candidate light
    before the camera exposes, as an uncalibrated LED would (``benchmarks.planner_sim_jpeg``);
    the candidates are shot first, so their noise stream is the same whatever the factors.
    """
    from rti_rig.simulator.ground_truth import homogeneous_directions

    scene, camera_shot = scene_camera(name, s)
    rng = np.random.default_rng(s.seed)

    def shoot(
        direction: NDArray[np.float64], noisy: bool, irradiance: float = 1.0
    ) -> NDArray[np.float32]:
        return camera_shot(direction, rng if noisy else None, irradiance=irradiance)

    cand = fibonacci_cap(s.candidates, 3.0, 87.0)
    factors = np.ones(len(cand)) if candidate_irradiance is None else candidate_irradiance
    factors = np.asarray(factors, dtype=np.float64)
    if factors.shape != (len(cand),):
        raise ValueError(f"candidate_irradiance: one factor per candidate ({len(cand)}) needed")
    # Held-out reference lights: a dense homogeneous set, offset from the candidates.
    gt = homogeneous_directions(s.ground_truth_lights)
    pick = np.random.default_rng(s.seed + 1).choice(len(gt), s.held_out_lights, replace=False)
    held = gt[np.sort(pick)]
    az, el = np.radians(s.preview_light_az_el_deg)
    preview_dir = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    return SceneData(
        name=name,
        normals=np.asarray(scene.normals, dtype=np.float64),
        candidate_dirs=cand,
        candidate_images=np.stack(
            [shoot(d, True, float(f)) for d, f in zip(cand, factors, strict=True)]
        ),
        held_dirs=held,
        held_images=np.stack([shoot(d, False) for d in held]),
        preview=shoot(preview_dir, True),
        passes=tuple(sorted(scene.passes)),
        material=scene.material,
    )


def normal_error(
    truth: NDArray[np.float64], images: NDArray, lights: NDArray[np.float64]
) -> tuple[float, float, float]:
    """Mean and median angle (°) of robust photometric stereo to ``truth`` over every pixel,
    and the solved fraction; unsolved pixels (or a refused fit) count as facing the camera."""
    from benchmarks.metrics import angular_error_deg
    from rti_rig.reconstruct import ReconstructionError, fit_photometric_stereo

    everywhere = np.ones(truth.shape[:2], dtype=bool)
    flat = np.array([0.0, 0.0, 1.0])
    try:
        ps = fit_photometric_stereo(images, lights, robust=True)
        est, valid = np.where(ps.valid[..., None], ps.normals, flat), float(ps.valid.mean())
    except ReconstructionError:
        est, valid = np.broadcast_to(flat, truth.shape), 0.0
    err = angular_error_deg(est, truth, everywhere)
    return float(err.mean), float(err.median), valid


def score_plan(
    data: SceneData, chosen: NDArray[np.intp]
) -> tuple[float, float, float, str, float, float]:
    """Normal error (robust PS, every pixel) and relighting quality of one plan."""
    from benchmarks.metrics import relight_psnr, relight_ssim
    from rti_rig.reconstruct import N_COEFFICIENTS, ReconstructionError, fit_model, select_model

    images = data.candidate_images[chosen]
    lights = data.candidate_dirs[chosen]
    mean, median, valid = normal_error(data.normals, images, lights)
    model, name = None, "none"
    try:
        choice = select_model(images, lights, holdout=min(5, len(chosen)))
        model, name = choice.fit(images, lights), choice.model
    except ReconstructionError:
        # Too few lights to hold any out: the light count alone decides the model.
        for candidate in ("ptm", "hsh1", "lambert"):
            if N_COEFFICIENTS[candidate] <= len(chosen):
                try:
                    model, name = fit_model(candidate, images, lights), f"{candidate} (forced)"
                    break
                except ReconstructionError:
                    continue
    if model is None:
        psnr = ssim = float("nan")
    else:
        psnr = relight_psnr(model, data.held_images, data.held_dirs, 1.0)
        ssim = relight_ssim(model, data.held_images, data.held_dirs, 1.0)
    return float(mean), float(median), valid, name, float(psnr), float(ssim)


def session_times(
    directions: NDArray[np.float64], dome: LoadedRig, arm: LoadedRig
) -> tuple[float, float]:
    """Session time of a plan on the simulated dome and on the simulated arm (seconds).

    Every figure is the shipped config's (``dome``, ``arm``: :func:`shipped_rig`), as
    ``rti-rig run`` reads it: a dome light costs :func:`per_light_s` of the dome, and the
    arm is the :class:`~rti_rig.simulator.sim_lights.SimulatedArm` ``run`` builds from the
    arm config's ``[arm]`` (speed, acceleration, resolution, band, park), its lamp switched
    on and off at each light and off at the start and the end (``light_switch_s`` each).
    Until 2026-12-02 the benchmark kept its own copy of them, with the dome's 0.1 s settle
    where the arm's config settles 0.3 s and one switch a light: every arm time was low by
    0.22 s a light and 0.04 s a session (docs/research/tradeoff.md).

    The dome takes the same time for every light. The arm visits the lights in the order
    ``rti-rig run`` gives a simulated arm (the move-time order of
    :func:`rti_rig.app.compose.arm_order_for`, from the park pose, by the model
    :func:`rti_rig.app.compose.simulated_arm_motion` makes of the arm's ``[arm]`` settings)
    and pays each move under its trapezoidal velocity profile. Before 2026-12-02 the arm went
    in nearest-neighbour order by angle, which ``run`` no longer uses for a simulated arm.
    Lights the arm cannot reach (inside its keep-out cone) are clamped to its band for timing.
    """
    from rti_rig.app.compose import simulated_arm_motion
    from rti_rig.planner.arm_order import order_for_arm

    dome_s = len(directions) * per_light_s(dome)
    carrier, geometry, clock, lit_s = timed_arm(arm)
    reachable = np.array([_clamp_to_band(d, geometry) for d in directions])
    # the lamp switched on before and off after each light, and off once at the start and
    # once at the end, as ``run`` does (the dry run's rig_time_s for the same lights)
    carrier.lamp(False)
    for i in order_for_arm(reachable, geometry.park_direction, simulated_arm_motion(arm)):
        carrier.move_to(reachable[i])
        carrier.lamp(True)
        clock.sleep(lit_s)
        carrier.lamp(False)
    carrier.lamp(False)
    carrier.park()
    return dome_s, clock.now()


def timed_arm(arm: LoadedRig) -> tuple[Any, ArmGeometry, VirtualClock, float]:
    """The :class:`~rti_rig.simulator.sim_lights.SimulatedArm` ``run`` builds from ``arm``'s
    config (speed, acceleration, resolution, lamp switch), connected, its geometry, a fresh
    virtual clock it runs on, and the seconds each light is lit (settle, expose, read out,
    transfer), all as the config says. Why one place: a test timing the arm in another order
    had built its own copy, and a copy's figures drift (this benchmark's own had been low by
    0.22 s a light)."""
    from rti_rig.app.config import rig_geometry
    from rti_rig.simulator.sim_lights import LightState, SimulatedArm

    geometry = rig_geometry(arm)
    settings, t = arm.config.arm, arm.config.timing
    assert isinstance(geometry, ArmGeometry) and settings is not None, arm.path
    clock = VirtualClock()
    carrier = SimulatedArm(
        geometry,
        LightState(),
        clock,
        speed_deg_s=settings.speed_deg_s,
        acceleration_deg_s2=settings.acceleration_deg_s2,
        resolution_deg=settings.resolution_deg,
        switch_s=t.light_switch_s,
    )
    carrier.connect()
    lit_s = t.settle_s + arm.config.camera.exposure_s + t.readout_s + t.transfer_s
    return carrier, geometry, clock, lit_s


def _clamp_to_band(d: NDArray[np.float64], arm: ArmGeometry) -> NDArray[np.float64]:
    from rti_rig.core.geometry import az_el_from_direction, direction_from_az_el

    az, el = az_el_from_direction(d)
    top = min(arm.max_elevation_deg, 90.0 - arm.keep_out_half_angle_deg - 1e-6)
    el = float(np.clip(el, arm.min_elevation_deg, top))
    return direction_from_az_el(float(az), el)


def run_tradeoff(
    s: TradeoffSettings, progress: Callable[[str], None] = print, done: list[Row] | None = None
) -> list[Row]:
    """Run the whole benchmark; returns one row per (scene, method, objective, floor, N).

    ``done``: a list the rows are added to a whole scene at a time, so a caller stopped
    midway (``bench tradeoff``'s Ctrl-C) keeps the scenes measured whole (minutes each)."""
    rows: list[Row] = [] if done is None else done
    for scene in s.scenes:
        t0 = time.perf_counter()
        data = render_scene_data(scene, s)
        progress(f"{scene}: rendered in {time.perf_counter() - t0:.1f} s")
        rows += run_scene(data, s, progress)
    return rows


#: The shipped rigs every plan is timed on (rig_configs/): every timing figure is theirs.
DOME_CONFIG = "simulated_dome.toml"
ARM_CONFIG = "virtual_arm.toml"


def shipped_rig(name: str) -> LoadedRig:
    """A shipped rig config, read as ``rti-rig run`` reads it: the benchmark's times are that
    rig's, with no second copy of a figure to drift from it."""
    from importlib import resources

    from rti_rig.app.config import load_rig_config

    return load_rig_config(str(resources.files("rti_rig.rig_configs").joinpath(name)))


def per_light_s(rig: LoadedRig) -> float:
    """Time a light costs besides any move: LED switch, settle, exposure, readout, transfer,
    the sum the controller's session estimate makes of ``[timing]`` and the camera's exposure."""
    t = rig.config.timing
    return t.light_switch_s + t.settle_s + rig.config.camera.exposure_s + t.readout_s + t.transfer_s


def plans(
    data: SceneData, s: TradeoffSettings
) -> Iterable[tuple[str, str, int, float, NDArray[np.intp], float]]:
    """Every plan for one rendered scene: (method, objective, N, floor, chosen, planning s)."""
    from rti_rig.core.errors import ScheduleError
    from rti_rig.planner.make_plan import make_plan
    from rti_rig.planner.uniform import select_uniform_leds

    dome = DomeGeometry(data.candidate_dirs, tuple(f"c{i:03d}" for i in range(s.candidates)))

    def idx(chosen: Iterable[int]) -> NDArray[np.intp]:
        return np.asarray(list(chosen), dtype=np.intp)

    for n in s.counts:
        if n > s.candidates:
            continue
        for floor in s.floors_deg:
            t = time.perf_counter()
            try:
                chosen = select_uniform_leds(dome, n, floor)
            except ScheduleError:  # fewer candidates above this floor than N: not a layout
                continue
            yield "uniform", "-", n, floor, idx(chosen), time.perf_counter() - t
        for method, objective in s.methods:
            if method == "uniform":
                continue
            t = time.perf_counter()
            sched = make_plan(
                data.preview, dome, n, method, objective, preview_light=s.preview_light_az_el_deg
            )
            leds = [int(step.led) for step in sched.steps if step.led is not None]
            yield method, objective, n, 0.0, idx(leds), time.perf_counter() - t


def run_scene(
    data: SceneData, s: TradeoffSettings, progress: Callable[[str], None] = print
) -> list[Row]:
    """Every plan for one rendered scene, scored and timed."""
    dome_rig, arm_rig = shipped_rig(DOME_CONFIG), shipped_rig(ARM_CONFIG)
    rows: list[Row] = []
    last_n = None
    for method, objective, n, floor, idx, plan_s in plans(data, s):
        if last_n is not None and n != last_n:
            progress(f"{data.name}: N={last_n} done")
        last_n = n
        rows.append(measured_row(data, method, objective, n, floor, idx, plan_s, dome_rig, arm_rig))
    if last_n is not None:
        progress(f"{data.name}: N={last_n} done")
    return rows


def lights_word(idx: Iterable[int]) -> str:
    """A plan's lights as results.csv's ``lights`` cell (:attr:`Row.lights`)."""
    return " ".join(str(int(i)) for i in idx)


def measured_row(
    data: SceneData,
    method: str,
    objective: str,
    n: int,
    floor: float,
    idx: NDArray[np.intp],
    plan_s: float,
    dome_rig: LoadedRig,
    arm_rig: LoadedRig,
) -> Row:
    """One plan scored and timed: the whole of a row (the run's, and a re-timed run's row
    whose plan changed since it was measured)."""
    scores = score_plan(data, idx)
    dome_s, arm_s = session_times(data.candidate_dirs[idx], dome_rig, arm_rig)
    return Row(
        data.name, method, objective, n, floor, *scores, dome_s, arm_s, plan_s,
        lights=lights_word(idx),
    )  # fmt: skip


def retime_arm(
    folder: Path,
    s: TradeoffSettings,
    progress: Callable[[str], None] = print,
    remeasured: list[str] | None = None,
) -> list[Row]:
    """Re-measure the arm time column of a run's ``results.csv`` in ``folder`` alone, and its
    two ``*_vs_arm_time.png`` plots: every plan made again, timed on :data:`ARM_CONFIG`, its
    scores kept (they do not depend on the arm). Minutes, where the whole run takes longer:
    for a change to the arm's timing, not to a plan or a score.

    A row whose plan is made again with other lights than the run measured (a planner that
    changed) is measured again whole, scores and times, and said by name: its scores had
    been kept beside the new plan's arm time, a row of two plans (14 rows of the optimal
    planner in docs/research/tradeoff.md's history). A run from before the ``lights`` column
    does not say its plans, so each is scored again and compared: the same scores are the
    same plan (kept as written), other scores a changed one. A row whose plan is no longer
    made at all is refused by name rather than kept with a time of another plan.
    ``remeasured``: gets each row measured again whole, by name."""
    import dataclasses

    path = folder / "results.csv"
    with path.open(newline="", encoding="utf-8") as f:
        recorded = list(csv.DictReader(f))
    fields = {f.name: f.type for f in dataclasses.fields(Row)}
    dome_rig, arm_rig = shipped_rig(DOME_CONFIG), shipped_rig(ARM_CONFIG)

    def as_row(r: dict[str, str]) -> Row:
        values: dict[str, Any] = {}
        for name, kind in fields.items():
            if name not in r:  # a column newer than the run (file_model): its default
                continue
            text = r[name]
            if kind in ("int", int):
                values[name] = int(text)
            elif kind in ("float", float):
                values[name] = float(text) if text != "" else float("nan")
            else:
                values[name] = text
        return Row(**values)

    def key_of(r: dict[str, str]) -> tuple[str, str, str, int, float]:
        return (r["scene"], r["method"], r["objective"], int(r["n"]), float(r["floor_deg"]))

    done: dict[int, Row] = {}  # by the row's place in results.csv
    for scene in dict.fromkeys(r["scene"] for r in recorded):
        data = render_scene_data(scene, s)
        made = {
            (scene, method, objective, n, floor): (idx, plan_s)
            for method, objective, n, floor, idx, plan_s in plans(data, s)
        }
        changed: list[str] = []
        for i, r in enumerate(recorded):
            if r["scene"] != scene:
                continue
            key = key_of(r)
            if key not in made:
                raise ValueError(f"{path}: no plan is made today for the row {key}")
            idx, plan_s = made[key]
            row = as_row(r)
            said = r.get("lights", "")
            if said == lights_word(idx):
                row.arm_time_s = session_times(data.candidate_dirs[idx], arm_rig, arm_rig)[1]
                done[i] = row
                continue
            again = measured_row(data, *key[1:], idx, plan_s, dome_rig, arm_rig)
            same = not said and all(
                np.isclose(getattr(again, k), getattr(row, k), rtol=1e-9, equal_nan=True)
                for k in ("normal_mean_deg", "normal_median_deg", "relight_psnr_db")
            )
            if same:  # a run from before the lights column, the same plan: its scores kept
                row.arm_time_s, row.lights = again.arm_time_s, again.lights
                done[i] = row
                continue
            done[i] = again
            changed.append(f"{key[1]}/{key[2]} N={key[3]} floor {key[4]:g}°")
        progress(f"{scene}: arm times re-measured")
        if remeasured is not None:
            remeasured += [f"{scene} {c}" for c in changed]
        if changed:
            progress(
                f"{scene}: {len(changed)} row(s) whose plan is not the one the run measured "
                "(other lights, or other scores where results.csv has no lights column) were "
                "measured again whole, scores and times: " + ", ".join(changed)
            )
    return [done[i] for i in range(len(recorded))]


def best_floor(rows: Iterable[Row], scene: str) -> float:
    """The uniform elevation floor with the lowest mean normal error over N (hindsight)."""
    by_floor: dict[float, dict[int, float]] = {}
    for r in rows:
        if r.scene == scene and r.method == "uniform":
            by_floor.setdefault(r.floor_deg, {})[r.n] = r.normal_mean_deg
    # Compare floors on the light counts every floor could do (a high floor has fewer LEDs).
    common = set.intersection(*(set(v) for v in by_floor.values()))
    return min(by_floor, key=lambda f: float(np.mean([by_floor[f][n] for n in common])))


def write_csv(rows: list[Row], path: Path, columns: list[str] | None = None) -> Path:
    """One line per row; a figure that does not apply (no arm on a replayed dome, no fit.rti
    written) is an empty cell, which a spreadsheet reads as missing, not the text "nan".
    ``columns``: those to write (default every field; a re-timed run keeps its own)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    names = columns or list(asdict(rows[0]))
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=names)
        writer.writeheader()
        for r in rows:
            cells = asdict(r)
            writer.writerow(
                {k: "" if isinstance(v, float) and np.isnan(v) else v for k, v in cells.items()}
                if columns is None
                else {
                    k: "" if isinstance(cells[k], float) and np.isnan(cells[k]) else cells[k]
                    for k in names
                }
            )
    return path


#: The naive uniform series' name when floor 0° is also the scene's best floor (one line).
NAIVE_IS_BEST = "uniform (floor 0°, also the best here)"


def _series(rows: list[Row], scene: str) -> dict[str, list[Row]]:
    """Rows per plotted series: naive uniform, uniform at the scene's best floor, planners."""
    floor = best_floor(rows, scene)
    out: dict[str, list[Row]] = {}
    for r in rows:
        if r.scene != scene:
            continue
        if r.method == "uniform":
            # when floor 0° is also the best floor, one line says so (two lines drawn on top
            # of each other had hidden the first under the second)
            if r.floor_deg == 0.0:
                label = "uniform" if floor != 0.0 else NAIVE_IS_BEST
                out.setdefault(label, []).append(r)
            elif r.floor_deg == floor:
                out.setdefault(f"uniform, floor {floor:g}°", []).append(r)
        else:
            out.setdefault(f"{r.method} ({r.objective})", []).append(r)
    return out


#: Tick values tried, coarsest first, in each decade of a log axis.
_LOG_TICK_SUBS = ((1.0,), (1.0, 2.0, 5.0), (1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0))


def _plain_log_ticks(ax: Any) -> None:
    """Label a log x axis with a few plain numbers (6, 8, 10), the coarsest set giving three.

    Left to matplotlib, an axis spanning less than a decade (an acquisition of 16 lights:
    N = 6…13) labels every minor tick in scientific notation, "6×10⁰ … 9×10⁰", which overlap
    into an unreadable run at the figure's size.
    """
    import math

    from matplotlib.ticker import FuncFormatter, NullFormatter

    xs = [x for line in ax.get_lines() for x in line.get_xdata() if np.isfinite(x) and x > 0]
    if not xs:
        return
    lo, hi = min(xs), max(xs)
    decades = range(math.floor(math.log10(lo)), math.floor(math.log10(hi)) + 1)
    ticks: list[float] = []
    for subs in _LOG_TICK_SUBS:
        ticks = [s * 10.0**k for k in decades for s in subs if lo <= s * 10.0**k <= hi]
        if len(ticks) >= 3:
            break
    if ticks:
        ax.set_xticks(ticks)
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v:g}"))
    ax.xaxis.set_minor_formatter(NullFormatter())


def plot(rows: list[Row], out_dir: Path) -> list[Path]:
    """Error against N and against session time, one figure per metric."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = sorted({r.scene for r in rows}, key=[r.scene for r in rows].index)
    paths = []
    for metric, label in (
        ("normal_mean_deg", "mean normal error (°)"),
        ("relight_psnr_db", "relighting PSNR (dB)"),
    ):
        for x_key, x_label, name in (
            ("n", "number of lights", "n"),
            ("dome_time_s", "session time on the dome (s)", "dome_time"),
            ("arm_time_s", "session time on the arm (s)", "arm_time"),
        ):
            fig, axes = plt.subplots(
                1, len(scenes), figsize=(4.2 * len(scenes), 3.6), squeeze=False
            )
            for ax, scene in zip(axes[0], scenes, strict=True):
                for series, rs in _series(rows, scene).items():
                    rs = sorted(rs, key=lambda r: r.n)
                    ax.plot(
                        [getattr(r, x_key) for r in rs],
                        [getattr(r, metric) for r in rs],
                        marker="o",
                        ms=3,
                        label=series,
                    )
                ax.set_xscale("log")
                _plain_log_ticks(ax)
                ax.set_title(scene)
                ax.set_xlabel(x_label)
                ax.grid(alpha=0.3)
            axes[0][0].set_ylabel(label)
            axes[0][-1].legend(fontsize=7)
            fig.tight_layout()
            path = out_dir / f"{metric.split('_')[0]}_vs_{name}.png"
            fig.savefig(path, dpi=90)
            plt.close(fig)
            paths.append(path)
    return paths


def _time_words() -> str:
    """What the session time (results.csv's ``dome_time_s``, ``arm_time_s``; the ``*_time``
    plots) counts, with the shipped configs' own figures. Why: the summary had said nothing
    of it, and a reader took it for the whole session a user waits (it is the rig time
    ``rti-rig run`` reports for the plan's lights, measured equal on both configs)."""
    dome, arm = shipped_rig(DOME_CONFIG), shipped_rig(ARM_CONFIG)
    return (
        "Session time (results.csv's dome_time_s and arm_time_s, the *_time plots) is the rig "
        'time `rti-rig run` reports ("Session time on the real rig") for the plan\'s lights: '
        f"on rig_configs/{DOME_CONFIG} {per_light_s(dome):.2f} s a light (LED switch, settle, "
        f"exposure, readout, transfer); on rig_configs/{ARM_CONFIG} "
        f"{per_light_s(arm) + arm.config.timing.light_switch_s:.2f} s a light (its settle, the "
        "lamp switched on and off) plus the arm's moves in run's order, its park and a "
        "lamp-off at each end. It leaves out connecting, the preview, planning (results.csv's "
        "plan_s), writing and fitting."
    )


def summarise(
    rows: list[Row], s: TradeoffSettings, seconds: float, command: str, stopped: str = ""
) -> str:
    """The markdown summary: tables per scene and plain statements of who wins where.

    ``stopped``: what a run stopped midway measured and what it did not, said first (its
    scenes are then those measured whole)."""
    lines = [
        "# Speed/accuracy trade-off",
        "",
        *([f"**{stopped}**", ""] if stopped else []),
        f"Measured with `{command}` in {seconds:.0f} s. Scenes {', '.join(s.scenes)} at "
        f"{s.size_px}×{s.size_px} px; candidates: {s.candidates} homogeneous dome positions "
        f"(3°–87°); relighting reference: {s.held_out_lights} held-out lights of a "
        f"{s.ground_truth_lights}-light homogeneous acquisition; preview lit from az/el "
        f"{s.preview_light_az_el_deg[0]:g}°/{s.preview_light_az_el_deg[1]:g}°. Normal error is "
        "the mean angle to the scene's true normals over all pixels of robust photometric "
        "stereo (unsolved pixels count); relighting PSNR is against noise-free renders under "
        "the held-out lights, with the model chosen from the acquired images by held-out "
        "error.",
        "",
        _time_words(),
        "",
    ]
    verdicts: list[str] = []
    for scene in dict.fromkeys(r.scene for r in rows):
        series = _series(rows, scene)
        lines += [f"## {scene}", "", "Mean normal error (°) / relighting PSNR (dB):", ""]
        names = list(series)
        lines.append("| N | " + " | ".join(names) + " |")
        lines.append("|---" * (len(names) + 1) + "|")
        counts = sorted({r.n for r in rows if r.scene == scene})
        for n in counts:
            cells = []
            for name in names:
                r = next((r for r in series[name] if r.n == n), None)
                cells.append(
                    "–" if r is None else f"{r.normal_mean_deg:.2f} / {r.relight_psnr_db:.1f}"
                )
            lines.append(f"| {n} | " + " | ".join(cells) + " |")
        lines.append("")
        verdicts += _verdicts(scene, series, counts)
    lines += ["## What the numbers say", "", *verdicts, ""]
    return "\n".join(lines)


def _verdicts(scene: str, series: dict[str, list[Row]], counts: list[int]) -> list[str]:
    def at(name: str, n: int) -> Row | None:
        return next((r for r in series.get(name, []) if r.n == n), None)

    # the naive series is named for what it is when floor 0° is also the best: every
    # comparison below had looked for "uniform", found nothing, and said "never worse" and
    # "never beats" of comparisons it had not made
    naive = NAIVE_IS_BEST if NAIVE_IS_BEST in series else "uniform"
    floor_name = next((k for k in series if k.startswith("uniform, floor")), naive)
    out = []
    pairs = {n: (a, b) for n in counts if (a := at("kmeans (normals)", n)) and (b := at(naive, n))}
    km = [n for n, (a, b) in pairs.items() if a.normal_mean_deg < b.normal_mean_deg]
    if not pairs:
        verdict = "was not compared with naive uniform (no N with both)"
    elif not km:
        verdict = "never beats naive uniform on normals"
    elif len(km) == len(pairs):
        verdict = "beats naive uniform on normals at every N"
    else:
        verdict = f"beats naive uniform on normals only at N = {', '.join(map(str, km))}"
    out.append(f"- **{scene}**: k-means (the paper's method) {verdict}.")
    for objective, key, better in (
        ("normals", "normal_mean_deg", lambda a, b: a < b),
        ("relight", "relight_psnr_db", lambda a, b: a > b),
    ):
        name = f"optimal ({objective})"
        worse = []
        gains = []
        compared = 0
        for n in counts:
            a, b = at(name, n), at(floor_name, n)
            if a is None or b is None:
                continue
            compared += 1
            va, vb = getattr(a, key), getattr(b, key)
            if not better(va, vb) and not np.isclose(va, vb, rtol=1e-3):
                worse.append(n)
            if n <= 10:
                gains.append(vb - va if key == "normal_mean_deg" else va - vb)
        unit = "°" if key == "normal_mean_deg" else " dB"
        if not compared:
            out.append(f"  - optimal/{objective} vs {floor_name}: not compared (no N with both).")
            continue
        out.append(
            f"  - optimal/{objective} vs {floor_name} on {key}: "
            + (f"worse at N = {', '.join(map(str, worse))}" if worse else "never worse")
            + (f"; mean gain at N ≤ 10: {np.mean(gains):+.2f}{unit}" if gains else "")
            + "."
        )
    return out


def main(argv: list[str] | None = None, settings: TradeoffSettings | None = None) -> None:
    """``python -m benchmarks.tradeoff --retime-arm FOLDER``: the arm time column alone.

    The whole run is ``rti-rig bench tradeoff --out FOLDER``; this re-measures a full run's
    arm times (:func:`retime_arm`) in place after a change to the arm's timing, and rewrites
    results.csv and the plots from it (the scores and the dome's plots are unchanged), and
    summary.md when a row was measured again whole (its tables had kept the old plan's
    scores). ``settings``: the run's (the full run's by default; a test's smaller one).

    A folder that is not a full simulated run is refused by name, as is a missing
    results.csv (a traceback had reached the user): a ``--quick`` run's plans are not the
    full settings' (120 candidates, not 240) and a ``--from`` run has no arm column."""
    import argparse
    import re

    from rti_rig.core.shell_words import shell_word

    ap = argparse.ArgumentParser(description=main.__doc__.split("\n")[0] if main.__doc__ else "")
    ap.add_argument(
        "--retime-arm",
        type=Path,
        required=True,
        metavar="FOLDER",
        help="a full run's folder (results.csv): re-measure its arm time column and arm plots",
    )
    args = ap.parse_args(argv)
    folder: Path = args.retime_arm
    path = folder / "results.csv"
    summary = folder / "summary.md"
    try:
        with path.open(newline="", encoding="utf-8") as f:
            columns = next(csv.reader(f))
        said = summary.read_text(encoding="utf-8") if summary.is_file() else ""
    except (OSError, StopIteration, UnicodeDecodeError) as exc:
        ap.error(f"{shell_word(path)}: {getattr(exc, 'strerror', None) or 'empty or not text'}")
    measured = re.search(r"Measured with `(.+?)` in (\d+) s", said)
    if settings is None and said and (measured is None or "--quick" in measured[1]):
        ap.error(
            f"{shell_word(folder)} is not a full simulated run (its summary.md says "
            + ("a --quick one" if measured else "another command")
            + "): --retime-arm re-times the full run's plans; run the benchmark again instead"
        )
    if "lights" not in columns:  # a run from before it: written now, its plans checked
        columns.append("lights")
    remeasured: list[str] = []
    try:
        rows = retime_arm(folder, settings or TradeoffSettings(), remeasured=remeasured)
    except (KeyError, ValueError) as exc:
        ap.error(f"{shell_word(path)}: {exc}")
    write_csv(rows, path, columns)
    plot(rows, folder)
    if remeasured and measured is not None:
        scenes = tuple(dict.fromkeys(r.scene for r in rows))
        s = replace(settings or TradeoffSettings(), scenes=scenes)
        # a stopped run's partial table stays one: its first line, which says so, had been
        # dropped, and the rewritten summary read as a whole run's
        stopped = re.search(r"^\*\*(Stopped \(.+)\*\*$", said, re.MULTILINE)
        text = summarise(rows, s, float(measured[2]), measured[1], stopped[1] if stopped else "")
        summary.write_text(text, encoding="utf-8")
        print(f"{shell_word(summary)} rewritten: {len(remeasured)} row(s) measured again whole")


if __name__ == "__main__":
    main()
