"""`.lp` files: the writer's profile, exact round trips, tolerant reading, precise rejection."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rti_rig.core.errors import LpFormatError
from rti_rig.core.lp_format import (
    LpEntry,
    format_lp,
    image_file_name,
    image_path,
    image_paths,
    missing_images_advice,
    parse_lp,
    read_lp,
    write_lp,
)

DATA = Path(__file__).resolve().parents[1] / "data"
# The profile of docs/conventions.md: count line, then 'name x y z' in fixed point 0.xxxxxx.
PROFILE_LINE = re.compile(r"^[^\s]+( -?0\.\d{6}){3}$")

unit = (
    st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3)
    .filter(lambda v: np.linalg.norm(v) > 1e-3)
    .map(lambda v: tuple(np.asarray(v) / np.linalg.norm(v)))
)


@given(st.lists(unit, min_size=1, max_size=40))
def test_round_trip_exact_to_1e6(dirs: list[tuple[float, float, float]]) -> None:
    entries = [LpEntry(f"image_{i + 1:03d}.jpg", d) for i, d in enumerate(dirs)]
    back = parse_lp(format_lp(entries))
    assert [e.name for e in back] == [e.name for e in entries]
    got = np.array([e.direction for e in back])
    np.testing.assert_allclose(got, np.array(dirs), atol=1e-6, rtol=0)


@given(st.lists(unit, min_size=1, max_size=40))
def test_written_lines_match_profile(dirs: list[tuple[float, float, float]]) -> None:
    text = format_lp([LpEntry(f"img_{i:04d}.jpg", d) for i, d in enumerate(dirs)])
    lines = text.split("\n")
    assert lines[0] == str(len(dirs))
    assert lines[-1] == ""  # LF-terminated, no CR anywhere
    assert "\r" not in text
    for line in lines[1:-1]:
        assert PROFILE_LINE.match(line), line


def test_axis_directions_never_write_one() -> None:
    text = format_lp([LpEntry("a_1.jpg", (0, 0, 1)), LpEntry("a_2.jpg", (-1, 0, 0))])
    assert "a_1.jpg 0.000000 0.000000 0.999999" in text
    assert "a_2.jpg -0.999999 0.000000 0.000000" in text
    values = [tok for line in text.splitlines()[1:] for tok in line.split()[1:]]
    assert len(values) == 6
    assert all(re.fullmatch(r"-?0\.\d{6}", v) for v in values), values


def test_real_dome_file_reads() -> None:
    entries = read_lp(DATA / "neuralrti" / "dirs.lp")
    assert len(entries) == 72
    assert entries[0].name == "image01.jpg"
    np.testing.assert_allclose(
        entries[0].direction, (0.205158607891401, -0.237020612397229, 0.949595268999854), atol=1e-12
    )
    d = np.array([e.direction for e in entries])
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12)
    assert np.all(d[:, 2] > 0)


def test_tolerant_reading() -> None:
    text = "2  \r\na_1.jpg\t0.6 0.0 0.8 \r\n\r\na_2.jpg  0 0 2\t\r\n\r\n"
    entries = parse_lp(text)
    assert [e.name for e in entries] == ["a_1.jpg", "a_2.jpg"]
    np.testing.assert_allclose(entries[1].direction, (0, 0, 1))  # renormalised
    no_count = parse_lp("x_1.jpg 0 0.6 0.8\nx_2.jpg 0.6 0 0.8\n")
    assert len(no_count) == 2
    # names with spaces still read (the first word is no image file name, or no number follows)
    spaced = parse_lp("IMG 001.jpg 0 0.6 0.8\nshot 2 b.tif 0.6 0 0.8\nmy photo.jpg x.jpg 0 0 1\n")
    assert [e.name for e in spaced] == ["IMG 001.jpg", "shot 2 b.tif", "my photo.jpg x.jpg"]


def test_each_light_keeps_its_line_and_equality_ignores_it() -> None:
    """The line a light was read from (for refusals a user corrects the file by), past a header
    comment, a count line and blank lines; equality is the light's, not where it was read."""
    text = "# dome A\n\n2\r\na_1.jpg 0.6 0.0 0.8\n\n\na_2.jpg 0 0 1\n"
    entries = parse_lp(text)
    assert [e.line for e in entries] == [4, 7]
    assert entries[1] == LpEntry("a_2.jpg", (0.0, 0.0, 1.0))
    assert len({entries[1], LpEntry("a_2.jpg", (0.0, 0.0, 1.0))}) == 1
    assert LpEntry("a_2.jpg", (0.0, 0.0, 1.0)).line is None


@pytest.mark.parametrize(
    ("text", "line", "fragment"),
    [
        ("2\na_1.jpg 0 0 1\na_2.jpg 0 x 1\n", 3, "y component 'x' is not a number"),
        ("1\na_1.jpg 0,5 0 1\n", 2, "decimal separator"),
        ("1\na_1.jpg 0 0 0\n", 2, "nearly) zero"),
        ("1\n../a_1.jpg 0 0 1\n", 2, "climbs out"),
        ("1\nsub/../../a_1.jpg 0 0 1\n", 2, "climbs out"),
        ("1\nsub\\..\\..\\a_1.jpg 0 0 1\n", 2, "climbs out"),
        # a '..' that stays inside is refused too, but not as climbing out: with the name to write
        ("1\nimgs/../a_1.jpg 0 0 1\n", 2, "steps back with '..' (an .lp's image names"),
        ("1\nimgs\\..\\x\\a_1.jpg 0 0 1\n", 2, "write it as 'x/a_1.jpg'"),
        ("1\nimgs\\x/../a_1.jpg 0 0 1\n", 2, "write it as 'imgs/a_1.jpg'"),
        ("1\nimgs/.. 0 0 1\n", 2, "names the .lp file's folder itself, not an image file"),
        ("2\na_1.jpg 0 0 1\na_1.jpg 0 1 0\n", 3, "already used on line 2"),
        ("1\na_1.jpg 0 0 nan\n", 2, "not finite"),
        ("1\na_1.jpg 0 1\n", 2, "expected 'name x y z'"),
        ("two\na_1.jpg 0 0 1\n", 1, "not a whole number"),
        # a column after the name (an intensity) is no name with a space in it
        ("1\na_1.jpg 0.6 0 0.8 1.0\n", 2, "found 5 fields"),
        ("1\na_1.JPG 1.0 0.6 0 0.8\n", 2, "before it 1.0 is an extra column"),
    ],
)
def test_malformed_files_name_line_and_reason(text: str, line: int, fragment: str) -> None:
    with pytest.raises(LpFormatError) as info:
        parse_lp(text, "plan.lp")
    assert info.value.line == line
    assert fragment in str(info.value)
    assert str(info.value).startswith(f"plan.lp, line {line}: ")


def test_absolute_names_as_rtibuilder_writes_them_are_read(tmp_path: Path) -> None:
    """RTIBuilder writes the image's path on the machine that built the project
    (``H:\\RTI_Data\\proj\\jpeg-exports\\proj_01.jpg``) into an .lp kept in assembly-files/:
    such files had been refused ("an absolute path"). The images are found by file name beside
    the .lp, in jpeg-exports/ beside it or beside its folder; relative names with backslashes
    as folders."""
    text = (
        "3\r\n"
        "H:\\RTI_Data\\proj\\jpeg-exports\\proj_01.jpg 0.1 0.2 0.97\r\n"
        "/home/me/proj/jpeg-exports/proj_02.jpg 0.2 0.1 0.97\r\n"
        "jpeg-exports\\proj_03.jpg -0.2 0.1 0.97\r\n"
    )
    entries = parse_lp(text, "proj.lp")
    assert [image_file_name(e.name) for e in entries] == [
        "proj_01.jpg",
        "proj_02.jpg",
        "proj_03.jpg",
    ]
    lp_dir = tmp_path / "proj" / "assembly-files"
    exports = tmp_path / "proj" / "jpeg-exports"
    lp_dir.mkdir(parents=True)
    exports.mkdir()
    for k in (1, 2):
        (exports / f"proj_0{k}.jpg").write_bytes(b"")
    assert image_path(lp_dir, entries[0].name) == exports / "proj_01.jpg"
    assert image_path(lp_dir, entries[1].name) == exports / "proj_02.jpg"
    (lp_dir / "proj_01.jpg").write_bytes(b"")  # beside the .lp comes first
    assert image_path(lp_dir, entries[0].name) == lp_dir / "proj_01.jpg"
    assert image_path(lp_dir, entries[2].name) == lp_dir / "jpeg-exports" / "proj_03.jpg"
    # nothing found: the file beside the .lp, for the caller's "missing" message
    assert image_path(lp_dir, "Z:\\x\\gone.jpg") == lp_dir / "gone.jpg"


def test_two_names_that_come_to_one_file_are_refused(tmp_path: Path) -> None:
    entries = parse_lp("2\nC:\\a\\x_1.jpg 0 0 1\nD:\\b\\x_1.jpg 0 1 1\n", "two.lp")
    with pytest.raises(LpFormatError, match="are both read from"):
        image_paths(tmp_path / "two.lp", entries)
    # an absolute name is never read at its own path (another machine's; any file)
    assert image_path(tmp_path, "/etc/passwd") == tmp_path / "passwd"


def test_the_writer_refuses_what_the_reader_would_not_read_back(tmp_path: Path) -> None:
    for name in ("pièce_1.jpg", "#1.jpg"):
        with pytest.raises(ValueError, match="not ASCII or starts with '#'"):
            format_lp([LpEntry(name, (0, 0, 1))])
    with pytest.raises(LpFormatError):
        write_lp(tmp_path / "missing" / "x.lp", [LpEntry("a.jpg", (0, 0, 1))])
    with pytest.raises(ValueError):
        write_lp(tmp_path / "x.lp", [LpEntry("é.jpg", (0, 0, 1))])
    assert not list(tmp_path.glob(".*tmp"))


def test_plan_labels_become_names_the_writer_takes() -> None:
    """plan --rig on an .lp of RTIBuilder's names (spaces, accents, one file name in two
    folders) had stopped with a traceback (whitespace, then UnicodeEncodeError)."""
    from rti_rig.app.usecases.plan import _lp_labels

    names = _lp_labels(
        [
            "H:\\Données RTI\\p\\pièce 01.jpg",
            "img_2.jpg",
            "C:\\a b\\img 2.jpg",
            "#3.jpg",
        ]
    )
    assert names == ["piece_01.jpg", "img_2.jpg", "img_2-2.jpg", "3.jpg"]
    format_lp([LpEntry(n, (0, 0, 1)) for n in names])


def test_comment_lines_are_skipped_and_said() -> None:
    notes: list[str] = []
    entries = parse_lp("# LP file from RTIBuilder, dome A\n1\na_1.jpg 0 0 1\n", "x.lp", notes=notes)
    assert [e.name for e in entries] == ["a_1.jpg"]
    assert notes == ["x.lp, line 1: comment line(s) starting with '#' skipped"]


def test_empty_and_missing(tmp_path: Path) -> None:
    with pytest.raises(LpFormatError, match="empty"):
        parse_lp("\n \n")
    with pytest.raises(LpFormatError, match="cannot read"):
        read_lp(tmp_path / "missing.lp")


def test_write_is_atomic_and_complete(tmp_path: Path) -> None:
    p = write_lp(tmp_path / "x.lp", [LpEntry("a_1.jpg", (0.6, 0, 0.8))])
    assert p.read_text() == "1\na_1.jpg 0.600000 0.000000 0.800000\n"
    assert not list(tmp_path.glob(".*tmp"))


def test_writer_refuses_bad_entries() -> None:
    with pytest.raises(ValueError, match="whitespace"):
        format_lp([LpEntry("a b.jpg", (0, 0, 1))])
    with pytest.raises(ValueError, match="at least one"):
        format_lp([])
    with pytest.raises(ValueError, match="at most 1000"):
        format_lp([LpEntry(f"a_{i}.jpg", (0, 0, 1)) for i in range(1001)])


def test_lights_below_the_object_plane_named_by_line_when_asked() -> None:
    """A rig's lights or a plan to run cannot point below the object plane; other tools'
    files are read as they are."""
    text = "3\nimage_1.jpg 0 0 1\nimage_2.jpg 0.6 0 -0.8\nimage_3.jpg 0 0.6 0.8\n"
    assert len(parse_lp(text, "mixed.lp")) == 3
    with pytest.raises(LpFormatError, match=r"mixed\.lp, line 3: .*below the object plane"):
        parse_lp(text, "mixed.lp", upper_hemisphere=True)
    # the horizon itself is allowed
    assert len(parse_lp("1\nimage_1.jpg 1 0 0\n", upper_hemisphere=True)) == 1


def test_count_line_that_disagrees_is_reported_and_the_lines_used() -> None:
    """A real dome file says 47 above 48 listed lights: the lines win, the note says so."""
    notes: list[str] = []
    text = "3\na_1.jpg 0 0 1\na_2.jpg 0 1 0\n"
    entries = parse_lp(text, "dome.lp", notes=notes)
    assert [e.name for e in entries] == ["a_1.jpg", "a_2.jpg"]
    assert notes == [
        "dome.lp, line 1: count line says 3 lights but the file lists 2; the 2 listed lights "
        "are used"
    ]
    notes.clear()
    assert len(parse_lp("1\na_1.jpg 0 0 1\na_2.jpg 0 1 0\n", "x.lp", notes=notes)) == 2
    assert "count line says 1 lights but the file lists 2" in notes[0]
    assert parse_lp("2\na_1.jpg 0 0 1\na_2.jpg 0 1 0\n", notes=(n := [])) and n == []


def test_a_missing_count_line_is_read_and_said() -> None:
    """A file with no count line is read from its lines, with a note giving the line to add:
    it had been read without a word, and the profile every known reader accepts opens with
    the count, so a file passed on from here could be refused there."""
    notes: list[str] = []
    entries = parse_lp("\n# dome A\na_1.jpg 0 0 1\na_2.jpg 0 1 0\n", "bare.lp", notes=notes)
    assert [e.name for e in entries] == ["a_1.jpg", "a_2.jpg"]
    assert notes[-1] == (
        "bare.lp, line 3: no count line (the .lp every known reader accepts opens with the "
        "number of lights); the 2 listed lights are used. To give it to another tool, add a "
        "first line '2'"
    ), notes


def test_light_a_hair_below_the_horizon_is_clamped_and_reported() -> None:
    """z = -0.0012 (calibration noise, seen in a real file) is kept at the horizon."""
    notes: list[str] = []
    text = "2\nimage_1.jpg 0.6 0.0 0.8\nimage_2.jpg 0.8 -0.6 -0.0012\n"
    entries = parse_lp(text, "real.lp", upper_hemisphere=True, notes=notes)
    d = np.array(entries[1].direction)
    assert d[2] == 0.0
    np.testing.assert_allclose(d, (0.8, -0.6, 0.0), atol=1e-12)
    assert len(notes) == 1 and notes[0].startswith("real.lp, line 3: light z = -0.0012")
    assert "clamped to z = 0" in notes[0]
    # read as other tools' files (no hemisphere rule) it is left as it is, silently
    notes.clear()
    assert parse_lp(text, "real.lp", notes=notes)[1].direction[2] < 0 and notes == []


def test_lower_than_the_tolerance_is_still_refused() -> None:
    text = "1\nimage_1.jpg 0.99 0.0 -0.011\n"
    with pytest.raises(LpFormatError, match=r"x\.lp, line 2: .*below the object plane"):
        parse_lp(text, "x.lp", upper_hemisphere=True, notes=[])


def test_read_lp_passes_notes(tmp_path: Path) -> None:
    p = tmp_path / "d.lp"
    p.write_text("5\nimage_1.jpg 1 0 -0.005\n", encoding="ascii")
    notes: list[str] = []
    (entry,) = read_lp(p, upper_hemisphere=True, notes=notes)
    assert entry.direction == (1.0, 0.0, 0.0)
    assert len(notes) == 2 and all(n.startswith(f"{p}, line ") for n in notes)


def test_vectors_far_from_unit_length_are_noted_rounding_noise_is_not() -> None:
    notes: list[str] = []
    parse_lp("2\na_1.jpg 0 0 3\na_2.jpg 0 2.9 0.5\n", "far.lp", notes=notes)
    assert len(notes) == 1 and notes[0].startswith("far.lp, line 2 and 1 more: light vector")
    assert "read as directions (normalised)" in notes[0]
    quiet: list[str] = []
    parse_lp("1\na_1.jpg 0.6001 0 0.8002\n", "near.lp", notes=quiet)
    assert quiet == []


# --- Files real tools write (sources: docs/conventions.md, "Files other tools write") ---------


def test_hp_ptmfitter_sample_file_reads() -> None:
    """HP Labs' "Making PTMs with a .lp File" sample (the PTMfitter's own example): absolute
    Windows paths, a run of spaces before the vector, and the last ring at z = -0.000204 (a hair
    below the horizon, clamped where lights must be above the plane)."""
    text = (
        "3\n"
        "C:\\Leaves512\\91-001.jpg       -0.015760 0.196076 0.980462\n"
        "C:\\Leaves512\\91-049.jpg       -0.950980 -0.309253 -0.000204\n"
        "C:\\Leaves512\\91-050.jpg       -0.587692 0.809084 -0.000204\n"
    )
    notes: list[str] = []
    entries = parse_lp(text, "leaves.lp", upper_hemisphere=True, notes=notes)
    assert [image_file_name(e.name) for e in entries] == ["91-001.jpg", "91-049.jpg", "91-050.jpg"]
    assert entries[1].direction[2] == 0.0 and entries[2].direction[2] == 0.0
    assert len(notes) == 2 and "clamped to z = 0" in notes[0]


def test_relight_savelp_output_reads() -> None:
    """relight's Project::saveLP (cnr-isti-vclab/relight, src/project.cpp) streams floats through
    Qt's QTextStream: six significant digits, so ``1``, ``0``, ``-0`` and exponents such as
    ``1e-05``; the image names are the folder's file names as they are (spaces included)."""
    text = (
        "3\nIMG 0001.jpg 0 0 1\nIMG 0002.jpg 1e-05 -0 1\n"
        "IMG 0003.jpg -0.707107 3.09086e-08 0.707107\n"
    )
    entries = parse_lp(text, "relight.lp")
    assert [e.name for e in entries] == ["IMG 0001.jpg", "IMG 0002.jpg", "IMG 0003.jpg"]
    np.testing.assert_allclose(entries[1].direction, (1e-05, 0, 1), atol=1e-9)
    np.testing.assert_allclose(entries[2].direction, (-0.707107, 0, 0.707107), atol=1e-6)


def test_relight_zero_direction_for_a_light_not_found_is_refused_naming_it() -> None:
    """relight's Project::saveLP writes ``0 0 0`` for an image whose light the sphere did not
    give (it warns "Missing N light directions" and saves all the same). Such a file is refused,
    and now the error names the image and says what the zero means and what to do (it had said
    only "is (nearly) zero: it has no orientation")."""
    text = "2\nimg_01.jpg 0.6 0 0.8\nimg_02.jpg 0 0 0\n"
    with pytest.raises(LpFormatError) as info:
        parse_lp(text, "relight.lp")
    message = str(info.value)
    assert message.startswith("relight.lp, line 3: ")
    assert "'img_02.jpg'" in message and "relight saves a missing direction as '0 0 0'" in message
    assert "remove the line" in message


def test_relight_json_dome_is_refused_as_json() -> None:
    """relight's dome calibration (``.dome``) and project (``.relight``) are JSON: given where an
    .lp goes, the error says so (it had been "count line '{' is not a whole number")."""
    text = '{\n    "label": "dome",\n    "directions": [{"x": 0.1, "y": 0.2, "z": 0.97}]\n}\n'
    with pytest.raises(LpFormatError) as info:
        parse_lp(text, "my.dome")
    assert str(info.value).startswith("my.dome, line 1: this is a JSON file, not an .lp")


def test_a_countless_lp_whose_first_image_name_begins_with_a_brace_is_read() -> None:
    """The JSON refusal looks at what the first line is: a count-less .lp whose first image is
    named '{001}.jpg' is a light, read as before (it had been refused as "a JSON file"), and a
    one-line JSON is still refused as JSON."""
    text = "{001}.jpg 0.6 0 0.8\n{002}.jpg 0 0.6 0.8\n"
    assert [e.name for e in parse_lp(text, "braces.lp")] == ["{001}.jpg", "{002}.jpg"]
    with pytest.raises(LpFormatError) as info:
        parse_lp('{"directions": [[0.1, 0.2, 0.97]]}\n', "my.dome")
    assert "this is a JSON file, not an .lp" in str(info.value)


def test_cceh_skeleton_without_names_is_refused_saying_so() -> None:
    """cceh/rti's lp-builder.py writes a dome's lights as bare ``x y z`` lines, no count and no
    names (``dome1.lp``, the "skeleton" its image-filer.py fills with names): there is no image
    to pair, so it is refused, and the error now says what the file is and what to add (it had
    been "expected 'name x y z', found 3 field(s)")."""
    text = "0.129535 0.129535 0.983078\n-0.129535 0.129535 0.983078\n"
    with pytest.raises(LpFormatError) as info:
        parse_lp(text, "dome1.lp")
    message = str(info.value)
    assert message.startswith("dome1.lp, line 1: expected 'name x y z', found three numbers")
    assert "lp-builder.py" in message and "put each image's file name before its light" in message


def test_cceh_image_filer_output_reads() -> None:
    """cceh/rti's image-filer.py (an early version) wrote ``# run of <date>`` above the count,
    and ``%f`` numbers, ``-0.000000`` included: read, the comment said in a note."""
    text = (
        "# run of 2018-11-11T22:38:29\n2\n"
        "DSC_2827.jpg 0.129535 0.129535 0.983078\n"
        "DSC_2828.jpg 0.469828 -0.000000 0.882758\n"
    )
    notes: list[str] = []
    entries = parse_lp(text, "sample.lp", notes=notes)
    assert [e.name for e in entries] == ["DSC_2827.jpg", "DSC_2828.jpg"]
    assert notes == ["sample.lp, line 1: comment line(s) starting with '#' skipped"]


def test_lpgen_tab_separated_lines_read() -> None:
    """lpgen (Michael Hodgson, 2011; a PTM light-position generator) writes the name, a tab,
    then the vector as the base file had it (spaces between the components)."""
    entries = parse_lp("2\nxx-001.tga\t-0.015760 0.196076 0.980462\nxx-002.tga\t0 0.6 0.8\n")
    assert [e.name for e in entries] == ["xx-001.tga", "xx-002.tga"]


def test_ptmfitter_image_endings_tell_an_extra_column() -> None:
    """HP's PTMfitter reads .tga and .ppm images: a number after such a name is a stray column,
    refused as one (it had been read as the name ``xx-001.tga 1.0``)."""
    for name in ("xx-001.tga", "xx-001.PPM"):
        with pytest.raises(LpFormatError, match=r"before it 1\.0 is an extra column"):
            parse_lp(f"1\n{name} 1.0 0.6 0 0.8\n", "ptm.lp")


def test_utf8_bom_from_windows_editors_reads(tmp_path: Path) -> None:
    """Notepad's "UTF-8 with BOM" and Windows PowerShell's ``Out-File -Encoding UTF8`` start
    the file with a byte-order mark: read as if it were not there."""
    p = tmp_path / "bom.lp"
    p.write_bytes("\ufeff2\r\na_1.jpg 0 0 1\r\na_2.jpg 0 0.6 0.8\r\n".encode())
    assert [e.name for e in read_lp(p)] == ["a_1.jpg", "a_2.jpg"]


def test_a_dos_eof_inside_the_file_is_still_refused_on_its_line() -> None:
    """Only Ctrl-Z after the last line is DOS's end-of-file mark: one with a light after it is
    no end of the file, and is refused on its line rather than the light dropped."""
    with pytest.raises(LpFormatError, match=r"line 3: expected 'name x y z', found 1 field"):
        parse_lp("2\na_1.jpg 0 0 1\n\x1a\na_2.jpg 0 0.6 0.8\n\x1a", "eof.lp")


def test_utf16_from_windows_powershell_or_notepad_reads(tmp_path: Path) -> None:
    """Windows PowerShell 5.1's ``>`` and ``Out-File`` write UTF-16 with a byte-order mark by
    default, as does Notepad's "Unicode"; relight reads such a file (Qt's QTextStream detects
    the mark). It had been refused as "count line 'ÿþ1\\x008\\x00' is not a whole number"."""
    text = "2\r\nH:\\Données\\a_1.jpg 0 0 1\r\na_2.jpg 0 0.6 0.8\r\n"
    for encoding in ("utf-16", "utf-16-be"):
        p = tmp_path / f"{encoding}.lp"
        raw = text.encode(encoding)
        p.write_bytes(raw if encoding == "utf-16" else b"\xfe\xff" + raw)
        entries = read_lp(p)
        assert [e.name for e in entries] == ["H:\\Données\\a_1.jpg", "a_2.jpg"], encoding


def test_nul_bytes_are_refused_saying_why(tmp_path: Path) -> None:
    """UTF-16 without a byte-order mark, or a file cut off while written (a card fills the rest
    with zeros): NUL bytes are no .lp text. The error says so on the line that holds them (it
    had shown the count line as '1\\x008\\x00', or a light line of NULs as one field)."""
    p = tmp_path / "nobom.lp"
    p.write_bytes("1\na_1.jpg 0 0 1\n".encode("utf-16-le"))
    with pytest.raises(LpFormatError, match=r"line 1: the line holds NUL bytes"):
        read_lp(p)
    cut = tmp_path / "cut.lp"
    cut.write_bytes(b"2\na_1.jpg 0 0 1\na_2.jpg 0 0.6 0.8\n" + b"\x00" * 64)
    with pytest.raises(LpFormatError, match=r"cut\.lp, line 4: the line holds NUL bytes"):
        read_lp(cut)


def test_vectors_all_of_one_length_are_told_that_length_not_a_range(tmp_path: Path) -> None:
    """Positions written 3 units out (every line): the note had said "length 3–3"."""
    from typer.testing import CliRunner

    from rti_rig.cli import app

    lp = tmp_path / "lamps.lp"
    lp.write_text("3\na_1.jpg 0 0 3\na_2.jpg 0 3 0.0001\na_3.jpg 3 0 0.0001\n")
    r = CliRunner().invoke(
        app, ["plan", "--rig", str(lp), "--lights", "3", "--out", str(tmp_path / "p.lp")]
    )
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert "line 2 and 2 more: light vector length 3, not 1" in text, text
    assert "3–3" not in text


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("3\nimg01.jpg,0.205,-0.237,0.949\n", "line 2: expected 'name x y z', found 1 field(s)"),
        ("3\r\nimg01.jpg;0,205;-0,237;0,949\r\n", "line 2: expected 'name x y z', found 1"),
        # '.' decimals, ', ' between fields: it had been told to use '.' as the decimal separator
        ("3\nimg01.jpg, 0.205, -0.237, 0.949\n", "line 2: x component '0.205,' is not a number"),
        ("name,x,y,z\nimg01.jpg,0.205,-0.237,0.949\n", "line 1: count line 'name,x,y,z'"),
    ],
)
def test_a_spreadsheets_csv_export_is_refused_saying_so(
    tmp_path: Path, text: str, says: str
) -> None:
    """Light lists edited in a spreadsheet and saved as CSV (',' or, where ',' is the decimal
    separator, ';'): refused with the line and what an .lp separates its fields with."""
    from typer.testing import CliRunner

    from rti_rig.cli import app

    lp = tmp_path / "lights.lp"
    lp.write_bytes(text.encode())
    r = CliRunner().invoke(
        app, ["plan", "--rig", str(lp), "--lights", "3", "--out", str(tmp_path / "p.lp")]
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and says in said, said
    assert "spreadsheet" in said and "spaces or tabs" in said
    assert "use '.' as the decimal separator" not in said


def test_decimal_commas_between_spaces_still_get_the_decimal_hint() -> None:
    with pytest.raises(LpFormatError, match=r"use '\.' as the decimal separator"):
        parse_lp("1\nimg01.jpg 0,205 -0,237 0,949\n", "x.lp")


def test_a_huge_finite_vector_is_read_as_its_direction() -> None:
    # its length had been computed as sqrt(x*x + ...), infinite for 1e308: read as (0, 0, 0),
    # the fit then refused "light 5 has length 0.0000" naming neither file nor line
    notes: list[str] = []
    (e,) = parse_lp("1\na.jpg 1e308 0 1e308\n", "x.lp", notes=notes)
    assert e.direction == pytest.approx((2**-0.5, 0.0, 2**-0.5))
    assert "x.lp, line 2" in " ".join(notes)


def test_missing_absolute_and_relative_names_are_told_where_each_goes(tmp_path: Path) -> None:
    """Missing images named both ways: a relative name goes where it points (it may name a
    subfolder), an absolute one by its file name into the .lp's folder, where it is read; it
    had been told to "copy them where their names point", the absolute one included."""
    names = ["sub/image02.jpg", "/nonexist/x/image01.jpg"]
    paths = [tmp_path / "sub" / "image02.jpg", tmp_path / "image01.jpg"]
    said = missing_images_advice(names, paths, tmp_path, "fit", total=3)
    assert said.endswith(
        "; copy them where their names point, an absolute name's file by its file name into "
        f"{tmp_path}, or remove their lines from the .lp to fit the others"
    ), said
    said = missing_images_advice(names, paths, tmp_path, "fit", total=2)
    assert "remove their lines" not in said, said


def test_an_absolute_names_folders_never_lead_out_of_the_lp_folder(tmp_path: Path) -> None:
    """The trailing components of an absolute name are tried under the .lp's folder; a ``..``
    among them ends the folders tried (a file above the .lp's folder is never read)."""
    lp_dir = tmp_path / "acq"
    (lp_dir / "sub").mkdir(parents=True)
    (tmp_path / "secret.jpg").write_bytes(b"outside")
    (lp_dir / "sub" / "a.jpg").write_bytes(b"a")
    assert image_path(lp_dir, "C:\\captures\\sub\\a.jpg") == lp_dir / "sub" / "a.jpg"
    assert image_path(lp_dir, "/mnt/c/captures/sub/a.jpg") == lp_dir / "sub" / "a.jpg"
    assert image_path(lp_dir, "C:\\x\\..\\..\\secret.jpg") == lp_dir / "secret.jpg"
    assert image_path(lp_dir, "C:\\x\\..\\sub\\a.jpg") == lp_dir / "sub" / "a.jpg"


def _ring(n: int, scale: float = 1.0) -> list[str]:
    """``n`` lights at 45° elevation round the object, each vector ``scale`` long."""
    c = scale * math.sqrt(0.5)
    return [
        f"image_{i + 1}.jpg {c * math.cos(i):.6f} {c * math.sin(i):.6f} {c:.6f}" for i in range(n)
    ]


def test_a_lone_vector_far_from_unit_length_is_refused_only_among_unit_vectors() -> None:
    """The rule fires where the other lines show the file is of unit vectors, and no sooner:
    lamp positions (every length alike, or spread about 1) are still read with a note."""
    lone = "image_x.jpg 0.2 0.1 0.09"  # length 0.24
    with pytest.raises(
        LpFormatError,
        match=r"d\.lp, line 4: light vector 0\.2 0\.1 0\.09 has "
        r"length 0\.241, where 3 of the file's 4 lights are unit vectors",
    ):
        parse_lp("\n".join([*_ring(3), lone]) + "\n", "d.lp")
    # two unit lines say too little of the file: noted, read
    notes: list[str] = []
    assert len(parse_lp("\n".join([*_ring(2), lone]) + "\n", "d.lp", notes=notes)) == 3
    assert "light vector length 0.241, not 1" in notes[0]
    # a quarter of the lines off unit length: not a lone typo, noted and read
    notes.clear()
    mixed = [*_ring(3), _ring(1, 3.0)[0].replace("image_1", "image_z")]
    assert len(parse_lp("\n".join([*mixed, lone.replace("x", "y")]) + "\n", notes=notes)) == 5
    # within 0.2 of unit length (0.849): lamp positions of a dome of about 1 m, read
    notes.clear()
    assert len(parse_lp("\n".join([*_ring(6), "a.jpg 0.6 0 0.6"]) + "\n", notes=notes)) == 7
    assert "light vector length 0.849, not 1" in notes[0]
    # all alike far from 1 (a file scaled by 3): noted, read
    notes.clear()
    assert len(parse_lp("\n".join(_ring(5, 3.0)) + "\n", notes=notes)) == 5
    assert "light vector length 3, not 1" in notes[0]


def test_a_clamped_light_is_still_checked_for_its_length() -> None:
    """A mistyped vector a hair below the plane (length 0.618 among unit vectors) had been
    clamped and accepted, where the same line a hair above the plane is refused: the clamp
    judged the clamped vector's length, not the file's."""
    units = [
        f"image{i:02}.jpg {math.cos(a):.6f} {math.sin(a):.6f} 0.000000"
        for i, a in enumerate(np.linspace(0.1, 6.0, 8))
    ]
    for z in ("-0.005", "0.005"):
        text = "\n".join([str(len(units) + 1), *units, f"bad.jpg 0.611811 -0.088872 {z}"]) + "\n"
        with pytest.raises(LpFormatError, match=r"line 10: light vector .* has length 0\.618"):
            parse_lp(text, "m.lp", upper_hemisphere=True, notes=[])


def test_the_clamp_note_gives_the_files_z_and_the_directions() -> None:
    """A vector of length 2 a hair below the plane: the note quotes the z the file holds (a
    user searches the file for it), and the direction's where the two differ."""
    notes: list[str] = []
    parse_lp("1\na.jpg 2 0 -0.01\n", "l.lp", upper_hemisphere=True, notes=notes)
    assert notes[0].startswith("l.lp, line 2: light z = -0.0100 (-0.0050 as a direction) is a hair")
    assert "light vector length 2" in notes[1]


@pytest.mark.parametrize("token", ["1_0", "０.5", "0.9_5", "٠.5"])
def test_numbers_only_c_and_qt_readers_take_are_read(token: str) -> None:
    """Python's float() reads '1_0' as 10 and full-width or Arabic-Indic digits as digits;
    relight's and RTIBuilder's readers do not, so such a file had passed `check` and been
    replayed. Refused with the line and the token, as '0x1p-1' is."""
    with pytest.raises(LpFormatError, match=rf"n\.lp, line 2: x component '{token}' is not a"):
        parse_lp(f"1\na.jpg {token} 0 1\n", "n.lp", notes=[])


@pytest.mark.parametrize("count", ["7_2", "７２"])
def test_a_count_line_only_c_and_qt_readers_take(count: str) -> None:
    with pytest.raises(LpFormatError, match=r"line 1: count line .* is not a whole number"):
        parse_lp(f"{count}\na.jpg 0 0 1\n", "n.lp", notes=[])


def test_the_numbers_real_tools_write_still_read() -> None:
    """relight's six significant digits with exponents, signs, a leading point, '72.0'."""
    notes: list[str] = []
    text = "3.0\na.jpg 1e-05 -0 1\nb.jpg +.6 0 .8\nc.jpg -0.707107 3.09086E-08 0.707107\n"
    assert len(parse_lp(text, "ok.lp", notes=notes)) == 3
    with pytest.raises(LpFormatError, match="is not finite"):
        parse_lp("1\na.jpg inf 0 1\n", "i.lp", notes=[])


@pytest.mark.parametrize("z", ["-1e-10", "-1.2e-16", "-9e-10"])
def test_float_noise_below_the_horizon_is_the_horizon(z: str) -> None:
    """z = -1e-10 was neither clamped (the clamp began at -1e-9) nor refused, kept negative,
    and then left out of every elevation band: a 72-image replay said it had 71 images."""
    notes: list[str] = []
    (entry,) = parse_lp(f"1\na.jpg 1.0 0.0 {z}\n", "h.lp", upper_hemisphere=True, notes=notes)
    assert entry.direction == (1.0, 0.0, 0.0) and notes == []


def test_a_comment_after_a_light_is_named_with_where_to_put_it() -> None:
    """It had been refused as "7 fields after the name", the '#' not named."""
    with pytest.raises(LpFormatError, match=r"line 3: a comment after the light: '# LED 2 weak'"):
        parse_lp("2\na.jpg 0 0 1\nb.jpg 0 0.6 0.8 # LED 2 weak\n", "c.lp", notes=[])


@pytest.mark.parametrize(
    ("raw", "said"),
    [
        # bytes of no text at all: said to be binary (a line number of random bytes meant
        # nothing, and the guesses below fit a text file)
        (bytes(range(256)) * 8, "this is a binary file (not text), not an .lp"),
        (np.random.default_rng(3).integers(0, 256, 3000, dtype=np.uint8).tobytes(), "binary"),
        # text in forms an .lp is met in: named as before
        ("2\na.jpg 0 0 1\nb.jpg 0 1 0\n".encode("utf-16-le"), "line 1: the line holds NUL"),
        (b"2\na.jpg 0 0 1\nb.jp" + b"\0" * 512, "line 3: the line holds NUL bytes"),
        # UTF-16 without a mark in a script whose characters have no zero byte
        ("2\nснимок1.jpg 0 0 1\nснимок2.jpg 0 1 0\n".encode("utf-16-le"), "line 1: the line"),
        ("2\nصورة١.jpg 0 0 1\nصورة٢.jpg 0 1 0\n".encode("utf-16-be"), "line 1: the line"),
    ],
    ids=["all-bytes", "random", "utf16-no-mark", "cut-off", "cyrillic-le", "arabic-be"],
)
def test_a_binary_file_is_told_apart_from_text_with_nul_bytes(
    tmp_path: Path, raw: bytes, said: str
) -> None:
    lp = tmp_path / "dirs.lp"
    lp.write_bytes(raw)
    with pytest.raises(LpFormatError) as info:
        read_lp(lp)
    assert said in str(info.value), str(info.value)


def test_a_folder_named_in_other_case_is_said_with_its_files(tmp_path: Path) -> None:
    """``JPEGS\\img00.jpg`` listed, the images in ``jpegs/``: Windows and macOS find them, so
    the .lp reads where it was written. Every image had been called missing, with the advice
    to copy them where they already were; the folder's case is now named, as a file's is."""
    from rti_rig.core.lp_format import case_hint, image_path

    (tmp_path / "jpegs").mkdir()
    for i in range(2):
        (tmp_path / "jpegs" / f"img0{i}.jpg").write_bytes(b"\xff\xd8\xff")
    missing = [image_path(tmp_path, f"JPEGS\\img0{i}.jpg") for i in range(2)]
    assert not any(p.exists() for p in missing)
    hint = case_hint(missing)
    assert "2 of them differ only in upper/lower case from a file there" in hint, hint
    assert "JPEGS/img00.jpg -> jpegs/img00.jpg" in hint, hint
    assert "rename the folder or correct the names in the .lp" in hint, hint
    # a folder that is not there in any case: nothing to name
    assert case_hint([image_path(tmp_path, "other\\img00.jpg")]) == ""


def test_utf16_with_its_mark_is_read_in_any_script(tmp_path: Path) -> None:
    """A review found UTF-16 (with its byte-order mark, which relight reads) of Cyrillic names
    called "a binary file" by the first form of the binary test."""
    lp = tmp_path / "dirs.lp"
    lp.write_bytes("\ufeff2\nснимок1.jpg 0 0 1\nснимок2.jpg 0 1 0\n".encode("utf-16-le"))
    assert [e.name for e in read_lp(lp)] == ["снимок1.jpg", "снимок2.jpg"]


def test_a_count_of_zero_or_below_disagrees_as_any_other_and_the_lines_are_used() -> None:
    """'0' or '-3' above listed lights is a count that disagrees: noted, the lines used, as 47
    above 48 is (it had been refused, "count 0 must be positive", with nothing to do); a file
    with no light line is still refused as such."""
    for count in ("0", "-3"):
        notes: list[str] = []
        entries = parse_lp(f"{count}\na_1.jpg 0 0 1\na_2.jpg 0 1 0\n", "c.lp", notes=notes)
        assert len(entries) == 2
        assert notes == [
            f"c.lp, line 1: count line says {count} lights but the file lists 2; the 2 listed "
            "lights are used"
        ]
    with pytest.raises(LpFormatError, match="no light lines after the count line"):
        parse_lp("0\n", "c.lp")


def test_a_name_no_file_here_can_have_is_refused_where_images_are_looked_up(
    tmp_path: Path,
) -> None:
    """Read, an .lp naming an image over 255 bytes is kept (a plan or a dome's calibration
    uses only its directions); looked up, it is refused by line (it had raised "File name
    too long"), and one looked up alone is simply not there."""
    long = "文" * 90 + ".jpg"
    lp = tmp_path / "x.lp"
    lp.write_text(f"2\na_1.jpg 0 0 1\n{long} 0 1 0\n", encoding="utf-8")
    entries = read_lp(lp)
    assert [e.name for e in entries] == ["a_1.jpg", long]
    assert image_path(tmp_path, long) == tmp_path / long  # not there, no OSError
    with pytest.raises(LpFormatError) as info:
        image_paths(lp, entries)
    assert info.value.line == 3
    assert "is 274 bytes long: no file or folder" in str(info.value)
    assert "rename it shorter and write the new name on this line" in str(info.value)


def test_an_absolute_names_folder_too_long_here_is_not_looked_for(tmp_path: Path) -> None:
    """A Windows tool's path whose folder is longer in UTF-8 than a name here can be: the
    file beside the .lp is found (looking the folder up had raised "File name too long")."""
    (tmp_path / "a_1.jpg").write_bytes(b"x")
    name = "C:\\caps\\" + "é" * 200 + "\\a_1.jpg"
    (entry,) = parse_lp(f"1\n{name} 0 0 1\n", "w.lp")
    assert image_path(tmp_path, entry.name) == tmp_path / "a_1.jpg"


def test_a_light_below_the_plane_is_refused_quoting_the_files_z() -> None:
    """The refusal quotes the z the line holds, and the direction's beside it where they
    differ: "z = -0.0101" had been said of a line written -0.0099 (length 0.98)."""
    text = "4\na_1.jpg 0.98 0 -0.0099\na_2.jpg 0 0 1\na_3.jpg 0 1 0.1\na_4.jpg 1 0 0.1\n"
    with pytest.raises(LpFormatError) as info:
        parse_lp(text, "b.lp", upper_hemisphere=True)
    assert "(z = -0.0099 (-0.0101 as a direction); less than 0.01 below" in str(info.value)
    with pytest.raises(LpFormatError) as info:
        parse_lp(text.replace("0.98 0 -0.0099", "0.9999 0 -0.0120"), "b.lp", upper_hemisphere=True)
    assert "(z = -0.0120; less than 0.01 below" in str(info.value)
