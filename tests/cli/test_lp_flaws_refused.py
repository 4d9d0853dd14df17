"""Flaws of a real `.lp` that each line alone would hide, refused at the front door.

Why: an audit found a z of 0.0949 typed for 0.949 normalised with a note and used about 55°
from where the light was (``check`` said PASS); a file cut off at ``0.`` made a zenith light a
horizon light; an image named ``#05.jpg`` skipped as a comment with one light fewer; and one
light 3° below the plane told to "check the sign convention". Each command that reads an
acquisition's ``.lp`` (plan, run, fit, check) must now refuse with the file, the line and the
way out, and touch nothing."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp

ACQ = Path(__file__).resolve().parents[2] / "tests" / "data" / "neuralrti_replay"
runner = CliRunner()


def _acquisition(tmp_path: Path, edit, *, newline_at_end: bool = True) -> Path:
    """A copy of the stored 18-light acquisition whose ``dirs.lp`` lines pass through ``edit``."""
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    lines = edit((acq / "dirs.lp").read_text().splitlines())
    (acq / "dirs.lp").write_text("\n".join(lines) + ("\n" if newline_at_end else ""))
    return acq / "dirs.lp"


def _set_field(lines: list[str], index: int, field: int, value: str) -> list[str]:
    fields = lines[index].split()
    fields[field] = value
    lines = list(lines)
    lines[index] = " ".join(fields)
    return lines


def _commands(lp: Path, tmp_path: Path) -> list[list[str]]:
    return [
        ["plan", "--rig", str(lp), "--lights", "6", "--out", str(tmp_path / "p.lp")],
        ["run", str(lp), "--out", str(tmp_path / "s"), "--lights", "6"],
        ["fit", str(lp.parent), "--out", str(tmp_path / "f")],
        ["check", str(lp)],
    ]


def _refused_everywhere(lp: Path, tmp_path: Path, *fragments: str) -> None:
    for args in _commands(lp, tmp_path):
        r = runner.invoke(app, args)
        text = " ".join(r.output.split())
        assert r.exit_code == 2, (args, r.output)
        assert all(f in text for f in fragments), (args, text)
        assert "Traceback" not in r.output
    assert not any((tmp_path / name).exists() for name in ("p.lp", "s", "f"))


def test_a_mistyped_z_among_unit_vectors_is_refused_naming_the_line(tmp_path: Path) -> None:
    # line 4 is image09.jpg, z 0.860181191949608: a 0 slipped in after the point
    lp = _acquisition(tmp_path, lambda lines: _set_field(lines, 3, 3, "0.0860181191949608"))
    _refused_everywhere(
        lp,
        tmp_path,
        f"{lp}, line 4:",
        "has length 0.517",
        "17 of the file's 18 lights are unit vectors",
        "correct the numbers on that line",
    )


def test_a_file_cut_off_mid_number_is_refused_as_cut_off(tmp_path: Path) -> None:
    lp = _acquisition(tmp_path, lambda lines: _set_field(lines, -1, 3, "0."), newline_at_end=False)
    _refused_everywhere(
        lp, tmp_path, f"{lp}, line 19:", "without a line break: cut off", "Copy it again"
    )


def test_one_light_below_the_plane_is_told_its_elevation_and_the_way_out(tmp_path: Path) -> None:
    # image09.jpg 3.0° below the horizon, a unit vector: sin(3°) = 0.0523, cos(3°) = 0.9986
    lp = _acquisition(
        tmp_path, lambda lines: [*lines[:3], "image09.jpg 0.9986 0 -0.0523", *lines[4:]]
    )
    _refused_everywhere(
        lp,
        tmp_path,
        f"{lp}, line 4:",
        "'image09.jpg' is 3.0° below the object plane",
        "set its z to 0",
        "remove the line and leave its image out",
    )
    text = " ".join(runner.invoke(app, _commands(lp, tmp_path)[0]).output.split())
    assert "sign convention" not in text and "negate" not in text


def test_a_file_with_z_down_is_told_to_negate_its_z_column(tmp_path: Path) -> None:
    def z_down(lines: list[str]) -> list[str]:
        for i in range(1, len(lines)):
            lines = _set_field(lines, i, 3, str(-float(lines[i].split()[3])))
        return lines

    lp = _acquisition(tmp_path, z_down)
    _refused_everywhere(
        lp,
        tmp_path,
        f"{lp}, line 2:",
        "18 of the file's 18 lights point below",
        "negate the z column",
    )


def test_an_image_named_with_a_hash_counted_by_the_count_line_is_refused(tmp_path: Path) -> None:
    lp = _acquisition(tmp_path, lambda lines: _set_field(lines, 3, 0, "#image09.jpg"))
    (lp.parent / "image09.jpg").rename(lp.parent / "#image09.jpg")
    _refused_everywhere(
        lp,
        tmp_path,
        f"{lp}, line 4:",
        "starts with '#' and is read as a comment",
        "says 18 lights and the file lists 17",
        "rename the image and its line",
        "write the count 17",
    )


@pytest.mark.parametrize("hashed", ["#image09.jpg", "# image09.jpg"])
def test_a_light_commented_out_with_the_count_corrected_is_skipped(
    tmp_path: Path, hashed: str
) -> None:
    """The count line agrees with the lights left: a light commented out on purpose, read."""

    def comment_out(lines: list[str]) -> list[str]:
        return ["17", *_set_field(lines, 3, 0, hashed)[1:]]

    lp = _acquisition(tmp_path, comment_out)
    r = runner.invoke(
        app, ["plan", "--rig", str(lp), "--lights", "6", "--out", str(tmp_path / "p.lp")]
    )
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert f"{lp}, line 4: comment line(s) starting with '#' skipped" in text
    # only a name touching its '#' may be an image's
    assert ("reads as a light" in text) == (hashed == "#image09.jpg")


def test_one_image_named_twice_says_which_lights_and_why(tmp_path: Path) -> None:
    """'./image05.jpg' and 'image05.jpg': one path written two ways, the two lights named."""

    def twice(lines: list[str]) -> list[str]:
        return _set_field(lines, 5, 0, "./" + lines[2].split()[0])

    lp = _acquisition(tmp_path, twice)
    r = runner.invoke(app, ["run", str(lp), "--out", str(tmp_path / "s"), "--lights", "6"])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, r.output
    assert "lights 2 and 5 of the file, 'image05.jpg' and './image05.jpg'" in text
    assert "one path written two ways" in text and "folders the .lp's machine had" not in text
    assert not (tmp_path / "s").exists()


def test_a_count_written_as_a_decimal_is_read_and_said(tmp_path: Path) -> None:
    lp = _acquisition(tmp_path, lambda lines: ["18.0", *lines[1:]])
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(lp), "--out", str(out), "--lights", "6"])
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert f"{lp}, line 1: count line '18.0' read as the count 18" in text
    assert len(read_lp(out / "lights.lp")) == 6
    # a count that is no whole number is still refused
    (lp).write_text(lp.read_text().replace("18.0", "18.5", 1))
    r = runner.invoke(app, ["run", str(lp), "--out", str(tmp_path / "s2"), "--lights", "6"])
    assert r.exit_code == 2 and "count line '18.5' is not a whole number" in r.output


def test_lines_with_the_name_last_are_told_the_order(tmp_path: Path) -> None:
    def name_last(lines: list[str]) -> list[str]:
        return [lines[0], *(" ".join([*ln.split()[1:], ln.split()[0]]) for ln in lines[1:])]

    lp = _acquisition(tmp_path, name_last)
    _refused_everywhere(
        lp,
        tmp_path,
        f"{lp}, line 2:",
        "gives the light before the image name ('x y z name')",
        "move each name to the front of its line",
    )


def test_an_invisible_character_in_a_name_is_shown_and_named(tmp_path: Path) -> None:
    def zero_width(lines: list[str]) -> list[str]:
        return [*lines[:2], lines[2].replace("image", "ima\u200bge", 1), *lines[3:]]

    lp = _acquisition(tmp_path, zero_width)
    for args in (
        ["run", str(lp), "--out", str(tmp_path / "s"), "--lights", "6"],
        ["fit", str(lp), "--out", str(tmp_path / "f")],
    ):
        r = runner.invoke(app, args)
        assert r.exit_code == 2, r.output
        text = " ".join(r.output.split())
        assert "('ima\\u200bge05.jpg')" in text, text
        assert "holds U+200B ZERO WIDTH SPACE, and image05.jpg is there" in text
        assert "delete it from the .lp" in text
        assert "copy them where their names point" not in text


def test_two_lights_of_one_direction_as_a_plans_rig_are_named_by_their_lines(
    tmp_path: Path,
) -> None:
    """As ``plan --rig``, an .lp is a dome of exactly its lights: a repeated direction is
    refused with both lights' numbers, image names and lines (past a header comment, the
    lines are not the numbers plus one)."""

    def repeat(lines: list[str]) -> list[str]:
        fields = lines[2].split()  # image05.jpg's light, given to image17.jpg (line 6)
        lines = _set_field(lines, 5, 1, fields[1])
        lines = _set_field(lines, 5, 2, fields[2])
        return ["# dome C, calibrated 2026-12", *_set_field(lines, 5, 3, fields[3])]

    lp = _acquisition(tmp_path, repeat)
    r = runner.invoke(app, _commands(lp, tmp_path)[0])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert (
        f"{lp}: lights 2 (line 4: image05.jpg) and 5 (line 7: image17.jpg) give the same "
        "direction; as --rig, an .lp means a dome with exactly these lights, each listed once "
        "(remove the repeats)" in text
    ), text
    assert "Traceback" not in r.output
    assert not (tmp_path / "p.lp").exists()
