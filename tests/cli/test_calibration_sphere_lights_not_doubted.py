"""A session of the black calibration sphere on the shipped simulated dome, every light right.

Its verdict had read "lights likely wrong: images under neighbouring recorded lights do not
look alike" (at 24 and 48 lights): the check compared the images' linear levels, where the
glossy sphere's highlight outweighs all the shading and two images whose highlights do not
overlap look no more alike than any other two. A user who shoots the sphere to measure a dome
was told to check an .lp that was right. The same images under a shuffled .lp are still
told, and so is a new dome's sphere session recorded under its stand-in layout
(tests/cli/test_lights_from_sphere.py).

On the virtual arm (24 lights) the same sphere then had four pairs of its right lights named
"wrong light: rendered 13-21× closer under the light recorded for … (swapped?)": the fit
places its images a median 56° from their lights, so which light renders one closer tells
nothing. A swap is still named where the fit places the lights (the brushed steel part:
tests/cli/test_qa_swap_where_directions_unjudged.py)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import said, shipped_variant
from typer.testing import CliRunner

from rti_rig.cli import app

LIKELY_WRONG = "images under neighbouring recorded lights do not look alike"


@pytest.fixture(scope="module")
def sphere_session(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """The shipped simulated dome, its scene the calibration sphere: 24 lights and the verdict
    of ``rti-rig run`` (read only)."""
    root = tmp_path_factory.mktemp("sphere")
    config = shipped_variant(root, "simulated_dome.toml", (('name = "relief"', 'name = "sphere"'),))
    out = root / "s"
    r = CliRunner().invoke(
        app, ["run", str(config), "--out", str(out), "--lights", "24"], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    return out, said(r)


def test_the_run_does_not_doubt_the_spheres_right_lights(sphere_session) -> None:  # type: ignore[no-untyped-def]
    _, text = sphere_session
    verdict = text.split("QA verdict: ")[1].split(" Next: ")[0]
    assert verdict.startswith("good"), verdict
    assert LIKELY_WRONG not in verdict and "likely wrong" not in verdict, verdict


def test_the_fit_does_not_doubt_them_either(sphere_session, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    session, _ = sphere_session
    out = tmp_path / "f"
    r = CliRunner().invoke(
        app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh"], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    qa = json.loads((out / "qa.json").read_text(encoding="utf-8"))
    assert qa["lights_likely_wrong"] is False, said(r)
    assert qa["verdict"].startswith("good"), qa["verdict"]


def test_a_shuffled_lp_of_the_same_images_is_still_told(sphere_session, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """The sphere's images with their .lp lines' lights shuffled (an .lp of another image
    order), imported as a folder with its .lp: the check still sees it."""
    session, _ = sphere_session
    folder = tmp_path / "acq"
    folder.mkdir()
    for image in sorted(session.glob("image_*.jpg")):
        shutil.copy2(image, folder / image.name)
    lines = (session / "lights.lp").read_text(encoding="utf-8").splitlines()
    count, rows = lines[0], [ln.split() for ln in lines[1:] if ln.strip()]
    order = np.random.default_rng(3).permutation(len(rows))
    shuffled = [f"{rows[i][0]} {' '.join(rows[j][1:])}" for i, j in enumerate(order)]
    (folder / "dirs.lp").write_text("\n".join([count, *shuffled]) + "\n", encoding="utf-8")
    out = tmp_path / "f"
    r = CliRunner().invoke(
        app,
        ["fit", str(folder / "dirs.lp"), "--out", str(out), "--no-ptm", "--no-hsh"],
        terminal_width=400,
    )
    assert r.exit_code == 0, r.output
    qa = json.loads((out / "qa.json").read_text(encoding="utf-8"))
    assert qa["lights_likely_wrong"] is True, said(r)
    assert LIKELY_WRONG in said(r), said(r)


def test_the_arm_names_no_pair_among_the_spheres_right_lights(tmp_path: Path) -> None:
    config = shipped_variant(
        tmp_path, "virtual_arm.toml", (('name = "relief"', 'name = "sphere"'),)
    )
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(config), "--out", str(out), "--lights", "24"], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    verdict = said(r).split("QA verdict: ")[1].split(" Next: ")[0]
    assert "(swapped?)" not in verdict and "wrong light:" not in verdict, verdict
    assert verdict.startswith("good"), verdict
