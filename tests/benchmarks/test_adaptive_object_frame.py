"""Layouts homogeneous about the object's mean normal (``planner.adaptive_object_frame``):
a level object gets exactly the camera-frame layout; a tilted one gets no light behind its
plane when the rig has enough in front of it."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.adaptive_object_frame import (
    mean_normal,
    object_frame_completion,
    tilt_deg,
    to_object_frame,
)
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.planner.adaptive import homogeneous_completion, start_subset


def _unit(az_deg: float, el_deg: float) -> np.ndarray:
    az, el = np.radians(az_deg), np.radians(el_deg)
    return np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])


def _start(cand: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """4 lights of the camera-frame 10° layout of ``n`` (as a session starts) and the mask of
    the lights left."""
    full = homogeneous_completion(cand, np.ones(len(cand), bool), np.zeros((0, 3)), n, 10.0)
    assert full is not None
    st = full[start_subset(cand[full], 4)]
    avail = np.ones(len(cand), bool)
    avail[st] = False
    return st, avail


@pytest.mark.parametrize("n", [6, 9, 12])
@pytest.mark.parametrize("floor", [0.0, 10.0, 20.0, 30.0])
def test_a_level_normal_gives_the_camera_frame_completion(n: int, floor: float) -> None:
    """Level (and tilted by less than MIN_TILT_DEG, the noise of a level object's estimate):
    the same lights as the camera-frame design, so a level object's choice is unchanged."""
    cand = fibonacci_cap(216, 3.0)
    st, avail = _start(cand, n)
    camera = homogeneous_completion(cand, avail, cand[st], n, floor)
    for normal in (np.array([0.0, 0.0, 1.0]), _unit(30.0, 84.0)):
        got = object_frame_completion(cand, avail, cand[st], n, floor, normal)
        assert got is not None and camera is not None
        assert sorted(got.tolist()) == sorted(camera.tolist())


@pytest.mark.parametrize("n", [6, 9, 12, 18])
@pytest.mark.parametrize("floor", [0.0, 10.0, 20.0])
def test_a_tilted_normal_takes_no_light_behind_the_plane(n: int, floor: float) -> None:
    """A plane facing azimuth 50°, elevation 40° (the simulator's tilted plane): every light
    the object-frame completion adds is above the floor measured from that plane (none behind
    it), while the camera-frame completion puts some below that floor or behind the plane."""
    cand = fibonacci_cap(216, 3.0)
    normal = _unit(50.0, 40.0)
    st, avail = _start(cand, n)
    got = object_frame_completion(cand, avail, cand[st], n, floor, normal)
    assert got is not None and len(got) == n - 4 and avail[got].all()
    above = np.degrees(np.arcsin(np.clip(cand[got] @ normal, -1.0, 1.0)))
    assert above.min() >= floor - 1e-9
    camera = homogeneous_completion(cand, avail, cand[st], n, floor)
    assert camera is not None
    if (n, floor) != (6, 0.0):  # what the object frame avoids (at 6 above 0° it adds none)
        el = np.degrees(np.arcsin(np.clip(cand[camera] @ normal, -1.0, 1.0)))
        assert el.min() < floor


def test_the_rotation_takes_the_normal_to_the_pole_and_the_estimate_is_robust() -> None:
    normal = _unit(50.0, 40.0)
    rot = to_object_frame(normal)
    assert np.allclose(rot @ normal, [0.0, 0.0, 1.0])
    assert np.allclose(rot @ rot.T, np.eye(3))
    assert np.allclose(to_object_frame(np.array([0.0, 0.0, 1.0])), np.eye(3))
    rng = np.random.default_rng(0)
    pixels = normal + 0.15 * rng.standard_normal((400, 3))
    pixels[:40] = [0.0, 0.0, 1.0]  # a tenth of the pixels a stand-in (level)
    pixels /= np.linalg.norm(pixels, axis=1, keepdims=True)
    assert abs(tilt_deg(mean_normal(pixels)) - 50.0) < 5.0
    assert np.allclose(mean_normal(np.full((3, 3), np.nan)), [0.0, 0.0, 1.0])


def test_the_probe_s_options_reach_it_and_its_command_line(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """``adaptive_reach --object-frame`` passes its draws, scenes, seed, measure and
    ``--true-normal`` to the probe and names them in the table's command line (which the docs
    quote as the command that measured it)."""
    import benchmarks.adaptive_reach as reach

    seen = {}

    def probe(draws, scenes, seed=0, measure="normals", true_normal=False):  # type: ignore[no-untyped-def]
        seen.update(draws=draws, scenes=scenes, seed=seed, measure=measure, true=true_normal)
        return ["| tilted | 6 | 30°: 0.21 |"]

    monkeypatch.setattr(reach, "object_frame", probe)
    argv = "--object-frame --true-normal --seed 1 --draws 3 --scenes tilted --measure relight"
    md = reach.main(argv.split())
    assert seen == dict(draws=3, scenes=("tilted",), seed=1, measure="relight", true=True)
    assert (
        "`python -m benchmarks.adaptive_reach --object-frame --true-normal --seed 1 "
        "--measure relight --draws 3 --scenes tilted`" in md
    )
    assert "scene's true median normal" in md and "| tilted | 6 | 30°: 0.21 |" in md
