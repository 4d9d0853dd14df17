"""The library scenes (coin, painting, tablet, …) in a simulated camera: banded, and the same.

A 24 MP dry run of the coin peaked near 9 GB: the renderer kept the scene's float64 planes
beside their float32 copies, swept each light's cast shadows over whole resampled grids and
rendered it as whole-frame float32 arrays converted to float64, and building the coin took
minutes (each legend stroke was evaluated over the whole frame). The measures here are
tracemalloc's (numpy reports its buffers to it) in units of one whole-image float64 radiance
array: bounded counts, independent of machine speed. The images and the scenes must not
change: both are compared, bit for bit, with the whole-image formulas.
"""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.simulator import scenes, shadows, sim_scene
from rti_rig.simulator.light_transport import light_at, render_radiance
from rti_rig.simulator.sim_camera import SimulatedCamera
from rti_rig.simulator.sim_lights import LightState
from rti_rig.simulator.sim_scene import LibraryRenderer, renderer_for

H, W = 300, 260  # several bands of rows, and not a multiple of the band height
RADIANCE_BYTES = H * W * 3 * 8
LIGHTS = [
    np.array(d) / np.linalg.norm(d)
    for d in ((0.3, -0.2, 0.93), (0.9, 0.25, 0.2), (-0.6, 0.7, 0.06), (0.0, 0.0, 1.0))
]


@pytest.fixture(autouse=True)
def _small_bands(monkeypatch: pytest.MonkeyPatch) -> None:
    """Bands of 23 rows: many bands in a small image, the last one ragged."""
    monkeypatch.setattr(sim_scene, "BAND_PIXELS", 23 * W, raising=False)


def _peak_while(fn):  # type: ignore[no-untyped-def]
    """``fn()``'s result, the most memory traced at once during it and what it still holds,
    both above what was held before."""
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        result = fn()
        held, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return result, peak - base, held - base


@pytest.mark.parametrize("name", scenes.SCENE_NAMES)
@pytest.mark.parametrize("distance_mm", [None, 240.0])
def test_the_banded_library_render_is_the_whole_image_render_bit_for_bit(name, distance_mm):
    render = renderer_for(name, H, W, seed=4, light_distance_mm=distance_mm)
    assert isinstance(render, LibraryRenderer)
    scene = scenes.make_scene(name, H, W, seed=4)
    for direction in LIGHTS:
        light = light_at(direction, distance_mm, irradiance=0.8)
        whole = render_radiance(scene, light).astype(np.float64)
        np.testing.assert_array_equal(render(direction, 0.8), whole)
        # a band pulled alone, after another light's (the shadow sweep is the light's own)
        np.testing.assert_array_equal(render.rows(direction, 0.8, 46, 69), whole[46:69])
    assert not render(None, 1.0).any()


def test_the_coin_renderer_keeps_only_the_shading_planes():
    renderer_for("coin", 16, 16, seed=0)  # the modules' own first allocations, apart
    render, _, held = _peak_while(lambda: renderer_for("coin", H, W, seed=0))
    # the float32 planes the shading reads (52 bytes a pixel: 2.2 radiance images); the
    # float64 scene (88 bytes a pixel) is let go once they are made: 3.7 were held before
    assert held < 2.6 * RADIANCE_BYTES, held / RADIANCE_BYTES
    assert render is not None


def test_a_coin_capture_sweeps_its_light_once_and_shades_in_bands():
    state = LightState()
    state.direction, state.intensity = LIGHTS[1], 1.0
    camera = SimulatedCamera(
        renderer_for("coin", H, W, seed=0, light_distance_mm=240.0),
        state,
        VirtualClock(),
        reference_exposure_s=0.05,
        seed=1,
    )
    camera.connect()
    frame, first, _ = _peak_while(lambda: camera.capture(0.05))
    # the visibility, the point light's sweep a block of rays at a time, and the banded
    # sensor chain (2.0); the sweep's whole polar grids, the whole-frame float32 render, its
    # float64 copy, the per-pixel light geometry and (at the first capture) the float32
    # planes made it 6.2
    assert first < 2.5 * RADIANCE_BYTES, first / RADIANCE_BYTES
    # a metering shot or a retry under the same light: the sweep is not run again, so only
    # the sensor chain and a band's temporaries (4.0 before: everything again)
    _, again, _ = _peak_while(lambda: camera.capture(0.02))
    assert again < 1.5 * RADIANCE_BYTES, again / RADIANCE_BYTES
    assert frame.pixels.shape == (H, W, 3)


def _legend_over_the_whole_frame(rng, u, v, rad):  # type: ignore[no-untyped-def]
    """The coin legend's definition, each stroke evaluated at every pixel (as it was built)."""
    legend = np.zeros(rad.shape)
    ang = np.arctan2(v, u)
    ring = (rad > 0.30) & (rad < 0.355)
    for k in range(28):
        a0 = -np.pi + 2 * np.pi * (k + 0.5) / 28
        if abs(a0 + np.pi / 2) < 0.35:
            continue
        for _ in range(int(rng.integers(2, 4))):
            tilt = rng.uniform(-0.8, 0.8)
            da = (ang - a0 + np.pi) % (2 * np.pi) - np.pi
            x_loc = da * rad - rng.uniform(-0.008, 0.008)
            y_loc = rad - 0.3275
            dist = np.abs(x_loc * math.cos(tilt) - y_loc * math.sin(tilt) * 0.3)
            np.maximum(legend, np.clip(1 - dist / 0.0035, 0, None) * ring, out=legend)
    return legend


@pytest.mark.parametrize(("rows", "cols", "seed"), [(8, 8, 0), (97, 131, 1), (400, 215, 2)])
def test_the_coin_legend_in_boxes_is_the_whole_frame_legend(rows, cols, seed):
    u, v, s = scenes._frame_grid(rows, cols)
    rad = np.hypot(u, v)
    got = scenes._coin_legend(np.random.default_rng(seed), u, v, rad, s)
    want = _legend_over_the_whole_frame(np.random.default_rng(seed), u, v, rad)
    np.testing.assert_array_equal(got, want)
    assert want.any() or rows < 16  # the strokes are there to compare


@pytest.mark.parametrize("name", ["coin", "tilted"])
def test_the_shadow_sweeps_in_blocks_are_the_whole_grid_sweeps(name, monkeypatch):
    """Each ray of a sweep is resampled and swept on its own: blocks of a few rays (ragged
    last block) give the cells one block of the whole grid gives."""
    height = scenes.make_scene(name, 97, 131, seed=2).height
    rng = np.random.default_rng(5)
    lamps = [
        (rng.uniform(-300, 400), rng.uniform(-300, 400), rng.uniform(2, 300)) for _ in range(6)
    ]
    lamps.append((65.0, 30.0, 40.0))  # the foot point inside the image
    directions = [LIGHTS[0], LIGHTS[1], LIGHTS[2], np.array([-0.7, -0.7, 0.14])]
    whole_grid = 1 << 40
    monkeypatch.setattr(shadows, "SWEEP_CELLS", whole_grid)
    want = [shadows.point_visibility(height, *lamp) for lamp in lamps]
    want += [shadows.directional_visibility(height, d) for d in directions]
    monkeypatch.setattr(shadows, "SWEEP_CELLS", 777)
    got = [shadows.point_visibility(height, *lamp) for lamp in lamps]
    got += [shadows.directional_visibility(height, d) for d in directions]
    for g, w in zip(got, want, strict=True):
        np.testing.assert_array_equal(g, w)
    assert any((w < 1).any() for w in want)  # shadows are there to compare
