"""The command line, end to end: the README's dry run, plans, exports and clear errors."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import numpy as np
import pytest
from conftest import REPO, SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.core.image_files import read_linear_tiff
from rti_rig.core.lp_format import read_lp

runner = CliRunner()


def readme_commands() -> list[str]:
    """The shell commands in the README's first code block (the two set-up commands)."""
    text = (REPO / "README.md").read_text(encoding="utf-8")
    block = re.search(r"```(?:sh|bash|console)?\n(.*?)```", text, re.DOTALL)
    assert block, "README must open with a code block holding the set-up commands"
    return [ln.strip() for ln in block.group(1).splitlines() if ln.strip() and ln[0] != "#"]


def readme_run_args() -> list[str]:
    """The arguments the README's first command passes to `rti-rig run`."""
    first = readme_commands()[0]
    part = first[first.index("rti-rig run") :]
    return shlex.split(part.split("&&")[0])[1:]


def brightest_azimuth_deg(lum: np.ndarray) -> float:
    """Azimuth (frame of docs/conventions.md) of the centroid of the brightest 2 % of pixels."""
    h, w = lum.shape
    top = lum >= np.quantile(lum, 0.98)
    rows, cols = np.nonzero(top)
    x = cols.mean() - (w - 1) / 2
    y = (h - 1) / 2 - rows.mean()
    return float(np.degrees(np.arctan2(y, x)) % 360)


@pytest.mark.slow
@pytest.mark.e2e
def test_readme_first_command_dry_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    args = readme_run_args()
    assert args[0] == "run" and args[1] == "rig_configs/simulated_dome.toml"
    out = tmp_path / "session"
    args[args.index("--out") + 1] = str(out)
    monkeypatch.chdir(REPO)
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "Session time on the real rig" in result.output

    entries = read_lp(out / "lights.lp")
    lines = (out / "lights.lp").read_text().splitlines()
    assert int(lines[0]) == len(lines) - 1 == len(entries)
    jpgs = sorted(p.name for p in out.glob("*.jpg"))
    assert [e.name for e in entries] == jpgs  # names match files, in name order
    assert len(jpgs) == 48

    # The brightest region moves with the light's azimuth (low rings: strong modelling).
    # Brightness is taken relative to the mean over all lights, so that albedo cancels.
    lum = np.stack(
        [
            read_linear_tiff(out / "linear" / e.name.replace(".jpg", ".tif")).mean(axis=-1)
            for e in entries
        ]
    )
    relative = lum / (lum.mean(axis=0) + 1.0)
    checked = 0
    for e, rel in zip(entries, relative, strict=True):
        az, el = az_el_from_direction(e.direction)
        if el > 30:
            continue
        got = brightest_azimuth_deg(rel)
        diff = (got - float(az) + 180) % 360 - 180
        assert abs(diff) < 25, (e.name, float(az), got)
        checked += 1
    assert checked == 24


@pytest.mark.e2e
def test_the_run_header_says_the_session_s_count_not_n_of_n(tmp_path: Path) -> None:
    """``--lights 24`` on the 48-LED dome had opened with "24 of 24 lights", which reads as if
    the dome had 24; a new session says its count, a resumed one what is left of it."""
    cfg = REPO / "rig_configs" / "simulated_dome.toml"
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "(dry run): 6 lights →" in r.output and " of 6 " not in r.output


def test_plan_then_run_then_export(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    plan = tmp_path / "plan.lp"
    r = runner.invoke(app, ["plan", "--rig", str(cfg), "--lights", "5", "--out", str(plan)])
    assert r.exit_code == 0, r.output
    assert len(read_lp(plan)) == 5
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--plan", str(plan)])
    assert r.exit_code == 0, r.output
    exported = tmp_path / "e.lp"
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(exported)])
    assert r.exit_code == 0, r.output
    assert exported.read_text() == (out / "lights.lp").read_text()
    np.testing.assert_allclose(
        [e.direction for e in read_lp(exported)], [e.direction for e in read_lp(plan)], atol=2e-6
    )
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(exported)])
    assert r.exit_code == 2 and "exists" in r.output
    lin = tmp_path / "lin.lp"
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(lin), "--linear"])
    assert r.exit_code == 0
    assert read_lp(lin)[0].name == "linear/image_001.tif"


@pytest.mark.e2e
def test_plan_on_bare_lp_keeps_original_names(tmp_path: Path) -> None:
    src = REPO / "tests" / "data" / "neuralrti" / "dirs.lp"
    plan = tmp_path / "p.lp"
    r = runner.invoke(app, ["plan", "--rig", str(src), "--lights", "9", "--out", str(plan)])
    assert r.exit_code == 0, r.output
    chosen = read_lp(plan)
    originals = {e.name: e.direction for e in read_lp(src)}
    assert len(chosen) == 9 and len({e.name for e in chosen}) == 9
    for e in chosen:
        np.testing.assert_allclose(e.direction, originals[e.name], atol=1e-6)


@pytest.mark.e2e
@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["run", "{cfg}", "--out", "{tmp}/s", "--lights", "99"], "only 12 LEDs"),
        (["run", "{tmp}/missing.toml", "--out", "{tmp}/s"], "cannot read the file"),
        (["run", "{cfg}", "--out", "{tmp}/s", "--plan", "{tmp}/bad.lp"], "bad.lp, line 2"),
        (["export-lp", "{tmp}", "--out", "{tmp}/x.lp"], "not an rti-rig session folder"),
        (["export-lp", "{tmp}/gone", "--out", "{tmp}/x.lp"], "gone does not exist"),
        (["export-lp", "{cfg}", "--out", "{tmp}/x.lp"], "is a file: give the session folder"),
        (["run", "{cfg}", "--out", "{tmp}/s", "--plan", "{tmp}/under.lp"], "under.lp, line 2"),
        (["run", "{cfg}", "--out", "{tmp}/s", "--auto-exposure", "--max-saturated", "2"], "[0, 1)"),
        # only metering reads it: accepted and ignored without --auto-exposure until 2026-11-29
        (
            ["run", "{cfg}", "--out", "{tmp}/s", "--max-saturated", "0.01"],
            "--max-saturated 0.01 sets how much --auto-exposure's metering lets clip",
        ),
        (
            ["preview", "{cfg}", "--out", "{tmp}/s", "--max-saturated", "0.01"],
            "add --auto-exposure, or drop --max-saturated",
        ),
        (["run", "{cfg}", "--out", "{tmp}/s", "--min-elevation-deg", "95"], "in [0, 90)"),
        (["check", "{cfg}", "--intensity", "1.5"], "--intensity 1.5: give the LED drive level"),
        (["check", "{cfg}", "--intensity", "0"], "fraction in (0, 1]"),
        (["plan", "--rig", "{cfg}", "--min-elevation-deg", "95", "--out", "{tmp}/p.lp"], "[0, 90)"),
        (["plan", "--rig", "{cfg}", "--lights", "5000", "--out", "{tmp}/p.lp"], "at most 1000"),
        (["plan", "--rig", "{tmp}/under.lp", "--out", "{tmp}/p.lp"], "below the object plane"),
        (["plan", "{tmp}", "--rig", "{cfg}", "--out", "{tmp}/p.lp"], "is a folder: give one"),
        (["plan", "--rig", "{cfg}", "--method", "magic", "--out", "{tmp}/p.lp"], "is not known"),
    ],
)
def test_errors_are_one_clear_line(tmp_path: Path, args: list[str], fragment: str) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    (tmp_path / "bad.lp").write_text("1\nimage_001.jpg 0 0 zero\n")
    (tmp_path / "under.lp").write_text("2\nimage_001.jpg 0.6 0 -0.8\nimage_002.jpg 0 0 1\n")
    argv = [a.format(cfg=cfg, tmp=tmp_path) for a in args]
    r = runner.invoke(app, argv)
    assert r.exit_code == 2, r.output
    assert fragment in said(r)
    assert "Traceback" not in r.output
    assert not (tmp_path / "s").exists() and not (tmp_path / "p.lp").exists()


@pytest.mark.e2e
def test_outputs_are_checked_before_work_and_inputs_never_replaced(tmp_path: Path) -> None:
    """A plan or .lp goes to a file in an existing folder; no input and no session file is
    ever replaced, even with --force."""
    cfg = write_config(tmp_path, SMALL_DOME)
    preview = tmp_path / "preview.png"
    preview.write_bytes((REPO / "tests" / "data" / "neuralrti" / "image11_small.jpg").read_bytes())
    before = preview.read_bytes()

    def plan(out: Path, *extra: str):  # type: ignore[no-untyped-def]
        args = ["plan", str(preview), "--rig", str(cfg), "--lights", "4", "--out", str(out)]
        return runner.invoke(app, [*args, *extra])

    r = plan(tmp_path / "nowhere" / "p.lp")
    assert r.exit_code == 2 and "folder" in r.output and "does not exist" in r.output
    assert not (tmp_path / "nowhere").exists()
    r = plan(tmp_path, "--force")
    assert r.exit_code == 2 and "is a folder" in r.output
    assert not list(tmp_path.glob(".*.tmp"))
    r = plan(preview, "--force")
    assert r.exit_code == 2 and "is the preview this command reads" in r.output
    assert preview.read_bytes() == before
    r = plan(cfg, "--force")
    assert r.exit_code == 2 and "is the rig file" in r.output

    session = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(session), "--lights", "4"])
    assert r.exit_code == 0, r.output
    own = (session / "lights.lp").read_text()
    r = runner.invoke(
        app, ["export-lp", str(session), "--out", str(session / "lights.lp"), "--linear", "--force"]
    )
    assert r.exit_code == 2 and "never overwritten" in said(r)
    assert (session / "lights.lp").read_text() == own
    r = plan(session / "lights.lp", "--force")
    assert r.exit_code == 2 and (session / "lights.lp").read_text() == own
    # a new file beside the session's own is fine
    r = runner.invoke(
        app, ["export-lp", str(session), "--out", str(session / "linear.lp"), "--linear"]
    )
    assert r.exit_code == 0, r.output
    assert read_lp(session / "linear.lp")[0].name == "linear/image_001.tif"


@pytest.mark.e2e
def test_plan_from_another_dome_is_refused(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    plan = tmp_path / "p.lp"
    plan.write_text("1\nimage_001.jpg 0.3 0.3 0.905539\n")
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--plan", str(plan)])
    assert r.exit_code == 2
    assert "no LED of this dome within" in said(r)
    assert not (tmp_path / "s").exists()


@pytest.mark.e2e
def test_help_explains_commands() -> None:
    r = runner.invoke(app, ["--help"])
    assert r.exit_code == 0
    for word in ("run", "plan", "export-lp", "relight"):
        assert word in r.output
    r = runner.invoke(app, ["run", "--help"])
    assert "--lights" in r.output and "--plan" in r.output and "--out" in r.output


def test_ci_runs_the_readme_test_command() -> None:
    commands = readme_commands()
    assert len(commands) >= 2 and "pytest" in commands[1]
    ci = (REPO / ".ci" / "run").read_text(encoding="utf-8")
    assert commands[1] in ci
    assert commands[0].replace(" || exit 1", "") in ci


@pytest.mark.e2e
@pytest.mark.parametrize("method", ["optimal", "kmeans"])
def test_plan_from_a_real_preview_on_a_bare_lp(tmp_path: Path, method: str) -> None:
    """The issue's CLI contract on real data: a preview of the 72-LED dome, its own .lp."""
    src = REPO / "tests" / "data" / "neuralrti" / "dirs.lp"
    preview = REPO / "tests" / "data" / "neuralrti" / "image11_small.jpg"
    plan = tmp_path / "p.lp"
    az, el = az_el_from_direction(read_lp(src)[10].direction)
    args = [
        "plan",
        str(preview),
        "--rig",
        str(src),
        "--lights",
        "9",
        "--method",
        method,
        "--preview-light",
        f"{float(az):.3f},{float(el):.3f}",
        "--out",
        str(plan),
    ]
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    chosen = read_lp(plan)
    originals = {e.name: e.direction for e in read_lp(src)}
    assert len(chosen) == 9 and len({e.name for e in chosen}) == 9
    for e in chosen:
        np.testing.assert_allclose(e.direction, originals[e.name], atol=1e-6)
    assert f"method {method}" in r.output


@pytest.mark.e2e
def test_preview_shot_then_plan_then_run(tmp_path: Path) -> None:
    """The product's loop: one preview shot on the rig, a plan from it, the session."""
    cfg = write_config(tmp_path, SMALL_DOME)
    shot = tmp_path / "preview"
    r = runner.invoke(app, ["preview", str(cfg), "--out", str(shot)])
    assert r.exit_code == 0, r.output
    assert f"rti-rig plan {shot} --rig {cfg}" in r.output
    az, el = az_el_from_direction(read_lp(shot / "lights.lp")[0].direction)
    # the small dome's LED at the default preview light (135°, 50°)
    assert (round(float(az)), round(float(el))) == (135, 50)
    plan = tmp_path / "plan.lp"
    args = ["plan", str(shot), "--rig", str(cfg), "--lights", "6", "--out", str(plan)]
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    assert "az 135.0°, el 50.0° (recorded by the session preview)" in r.output
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--plan", str(plan)])
    assert r.exit_code == 0, r.output
    assert len(read_lp(out / "lights.lp")) == 6


@pytest.mark.parametrize(
    ("extra", "fragment"),
    [
        (["--preview-light", "north"], "give azimuth and elevation"),
        (["--preview-light", "10,95"], "outside 0..90"),
        (["--objective", "beauty"], "--objective 'beauty' is not known"),
        (["--depth-model", "{tmp}/none.onnx"], "file not found"),
        (["--depth-model", "{tmp}"], "is a folder: give the model file in it (.onnx)"),
    ],
)
def test_plan_option_errors(tmp_path: Path, extra: list[str], fragment: str) -> None:
    preview = REPO / "tests" / "data" / "neuralrti" / "image11_small.jpg"
    args = [
        "plan",
        str(preview),
        "--rig",
        str(REPO / "tests" / "data" / "neuralrti" / "dirs.lp"),
        "--out",
        str(tmp_path / "p.lp"),
        *[a.format(tmp=tmp_path) for a in extra],
    ]
    r = runner.invoke(app, args)
    assert r.exit_code == 2, r.output
    assert fragment in said(r)
    r = runner.invoke(
        app,
        [
            "plan",
            "--rig",
            str(REPO / "tests" / "data" / "neuralrti" / "dirs.lp"),
            "--method",
            "kmeans",
            "--out",
            str(tmp_path / "q.lp"),
        ],
    )
    assert r.exit_code == 2 and "give PREVIEW" in r.output


@pytest.mark.e2e
def test_plan_optimal_without_a_preview(tmp_path: Path) -> None:
    """`optimal` needs no preview: it plans for a level, matte surface and says so."""
    rig = REPO / "tests" / "data" / "neuralrti" / "dirs.lp"
    out = tmp_path / "flat.lp"
    r = runner.invoke(
        app, ["plan", "--rig", str(rig), "--method", "optimal", "--lights", "9", "--out", str(out)]
    )
    assert r.exit_code == 0, r.output
    assert "no preview" in r.output
    names = {e.name for e in read_lp(rig)}
    planned = read_lp(out)
    assert len(planned) == 9 and {e.name for e in planned} <= names
    r = runner.invoke(
        app,
        [
            "plan",
            "--rig",
            str(rig),
            "--method",
            "optimal",
            "--preview-light",
            "30,50",
            "--out",
            str(tmp_path / "x.lp"),
        ],
    )
    assert r.exit_code == 2 and "no preview was given" in said(r)
    assert not (tmp_path / "x.lp").exists()


@pytest.mark.slow
@pytest.mark.e2e
def test_plan_signal_noise(tmp_path: Path) -> None:
    """--signal-noise reaches the planner (its report line is printed) and bad values are
    refused before anything is written."""
    rig = REPO / "tests" / "data" / "neuralrti" / "dirs.lp"
    base = ["plan", "--rig", str(rig), "--method", "optimal", "--lights", "12"]
    r = runner.invoke(app, [*base, "--signal-noise", "0.05", "--out", str(tmp_path / "a.lp")])
    assert r.exit_code == 0, r.output
    assert "5 % of the signal" in r.output and len(read_lp(tmp_path / "a.lp")) == 12
    r = runner.invoke(app, [*base, "--signal-noise", "5", "--out", str(tmp_path / "b.lp")])
    assert r.exit_code == 2 and "--signal-noise must be a fraction" in said(r)
    assert not (tmp_path / "b.lp").exists()
    # checked before the rig and the output file: the option's own error, not "exists"
    r = runner.invoke(app, [*base, "--signal-noise", "-1", "--out", str(tmp_path / "a.lp")])
    assert r.exit_code == 2 and "--signal-noise must be a fraction" in said(r)


def _rig_with_signal_noise(tmp_path: Path, value: str) -> Path:
    text = (REPO / "rig_configs" / "simulated_dome.toml").read_text()
    rig = tmp_path / "jpeg_dome.toml"
    rig.write_text(text.replace("[camera]\n", f"[camera]\nsignal_noise = {value}\n", 1))
    return rig


@pytest.mark.slow
@pytest.mark.e2e
def test_plan_takes_signal_noise_from_the_rig_config(tmp_path: Path) -> None:
    """A rig declares its images' signal-proportional noise once ([camera] signal_noise); the
    flag overrides it; an objective that cannot model it is refused, naming the file."""
    rig = _rig_with_signal_noise(tmp_path, "0.05")
    base = ["plan", "--rig", str(rig), "--method", "optimal", "--lights", "12"]
    r = runner.invoke(app, [*base, "--out", str(tmp_path / "a.lp")])
    assert r.exit_code == 0, r.output
    flat = said(r)
    assert "5 % of the signal" in flat
    # where the evidence says it costs, and how to turn the rig's setting off for one plan
    assert "brushed steel from 12 lights" in flat and "give --signal-noise 0" in flat
    r = runner.invoke(app, [*base, "--signal-noise", "0", "--out", str(tmp_path / "b.lp")])
    assert r.exit_code == 0, r.output
    assert "of the signal" not in r.output
    r = runner.invoke(app, [*base, "--objective", "relight", "--out", str(tmp_path / "c.lp")])
    flat = said(r)
    assert r.exit_code == 2 and "jpeg_dome.toml" in flat and "[camera] signal_noise" in flat
    assert not (tmp_path / "c.lp").exists()
    bad = _rig_with_signal_noise(tmp_path, "1.5")
    r = runner.invoke(app, ["plan", "--rig", str(bad), "--out", str(tmp_path / "d.lp")])
    flat = said(r)
    assert r.exit_code == 2 and "signal_noise" in flat and "jpeg_dome.toml" in flat


@pytest.mark.e2e
def test_no_file_of_a_session_or_of_the_rig_is_replaced(tmp_path: Path) -> None:
    """Not even a captured image in a session's subfolder, nor the dome's LED calibration."""
    cfg = write_config(tmp_path, SMALL_DOME)
    session = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(session), "--lights", "4"])
    assert r.exit_code == 0, r.output
    tif = session / "linear" / "image_001.tif"
    before = tif.read_bytes()
    r = runner.invoke(app, ["export-lp", str(session), "--out", str(tif), "--force"])
    assert r.exit_code == 2 and "never overwritten" in said(r)
    assert tif.read_bytes() == before

    (tmp_path / "domes").mkdir()
    lp = tmp_path / "domes" / "my.lp"
    lp.write_text("3\nled_1.jpg 0 0.6 0.8\nled_2.jpg 0.6 0 0.8\nled_3.jpg 0 0 1\n")
    text = SMALL_DOME.replace('layout = "rings"', 'layout = "lp"\nlp_file = "domes/my.lp"')
    text = text.split("rings = [")[0] + "\n[camera]" + text.split("[camera]")[1]
    lp_cfg = write_config(tmp_path, text, "lp_dome.toml")
    calibration = lp.read_text()
    r = runner.invoke(
        app, ["plan", "--rig", str(lp_cfg), "--lights", "3", "--out", str(lp), "--force"]
    )
    assert r.exit_code == 2 and "LED calibration" in said(r)
    assert lp.read_text() == calibration


@pytest.mark.slow
@pytest.mark.e2e
def test_plan_orders_an_arm_by_move_time_with_its_servo_settings(tmp_path: Path) -> None:
    """``rti-rig plan`` on an arm with ``[arm.dynamixel]`` fires its stops in the move-time
    order of ``rti_rig.planner.arm_order`` (the issue's "move-time order for arms"), which here is
    faster than the nearest-neighbour fallback."""
    from rti_rig.app.config import load_rig_config, rig_geometry
    from rti_rig.core.arm_motion import sequence_time_s
    from rti_rig.planner.arm_order import order_for_arm
    from rti_rig.planner.uniform import order_nearest_neighbour

    rig = REPO / "rig_configs" / "simulated_arm.toml"
    plan = tmp_path / "plan.lp"
    args = ["plan", "--rig", str(rig), "--lights", "12", "--method", "optimal"]
    r = runner.invoke(app, [*args, "--out", str(plan)])
    assert r.exit_code == 0, r.output
    loaded = load_rig_config(rig)
    settings = loaded.config.arm.dynamixel
    park = rig_geometry(loaded).park_direction
    dirs = np.array([e.direction for e in read_lp(plan)])
    planned = sequence_time_s(dirs, settings, park)
    best = sequence_time_s(dirs[order_for_arm(dirs, park, settings)], settings, park)
    nearest = sequence_time_s(dirs[order_nearest_neighbour(dirs, park)], settings, park)
    assert planned == pytest.approx(best, rel=1e-3)
    assert planned < nearest * 0.99
