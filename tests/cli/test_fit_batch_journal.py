"""A batch tells an image edited in place, and says when the journal it relied on is lost.

An image edited in place (same name, different bytes) kept the checksum its journal took at
capture, so the batch's record matched and the out-of-date fit stood ("skipped (finished
earlier)"); only a new fit's QA found it. And a session whose journal was lost since its fit
was refitted as "6 of 6 images changed", which no image had: the batch compared the journal's
checksums with sizes and times, and did not say the journal was gone.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from pathlib import Path
from typing import Any

import pytest
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def batch(*sources: Path, out: Path):  # type: ignore[no-untyped-def]
    """``rti-rig fit S... --out OUT`` as a user runs it (PS: any light count from 3 fits)."""
    args = ["fit", *map(str, sources), "--out", str(out), "--model", "ps", "--no-qa"]
    return runner.invoke(app, args)


def fitted(tmp_path: Path) -> tuple[Path, Path, Path]:
    """Sessions S and T (6 lights each), fitted by a batch into FB: (S, T, FB)."""
    cfg = write_config(tmp_path, SMALL_DOME)
    s, t, fb = tmp_path / "S", tmp_path / "T", tmp_path / "FB"
    for session in (s, t):
        r = runner.invoke(app, ["run", str(cfg), "--out", str(session), "--lights", "6"])
        assert r.exit_code == 0, r.output
    r = batch(s, t, out=fb)
    assert r.exit_code == 0 and said(r).count(": done") == 2, r.output
    return s, t, fb


def later(path: Path) -> None:
    """Give ``path`` a modification time a second after its own (an edit, a ``touch``)."""
    st = path.stat()
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))


@pytest.mark.e2e
@pytest.mark.slow
def test_an_image_edited_in_place_is_refitted_and_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    s, t, fb = fitted(tmp_path)
    hashed: list[Path] = []
    real = hashlib.file_digest

    def counted(fh: Any, digest: Any) -> Any:  # every image file the batch reads to hash it
        hashed.append(Path(fh.name))
        return real(fh, digest)

    monkeypatch.setattr(hashlib, "file_digest", counted)
    r = batch(s, t, out=fb)
    assert said(r).count("skipped (finished earlier)") == 2, r.output
    assert hashed == []  # nothing changed in size or time: nothing read

    tif = s / "linear" / "image_003.tif"
    data = bytearray(tif.read_bytes())
    data[-100] ^= 0xFF  # same name, same size, other content
    tif.write_bytes(bytes(data))
    later(tif)
    r = batch(s, t, out=fb)
    assert r.exit_code == 0, r.output
    assert (
        f"{s}: refitted (its session changed since the earlier fit: 1 of 6 images changed on "
        "disk since their capture (same name, not the checksum their journal took): "
        "image_003)" in said(r)
    ), r.output
    assert f"{t}: skipped (finished earlier)" in said(r), r.output
    assert hashed == [tif]  # only the image whose time changed was read

    r = batch(s, t, out=fb)  # refitted from the image as it now is: it stands
    assert said(r).count("skipped (finished earlier)") == 2, r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_a_lost_journal_is_said_and_the_images_judged_by_size_and_time(tmp_path: Path) -> None:
    s, t, fb = fitted(tmp_path)
    journal = s / "journal.jsonl"
    # moved aside, not into tmp_path: a folder holding a journal is a session folder, and the
    # batch's --out (tmp_path/FB) would be inside it
    (tmp_path / "aside").mkdir()
    shutil.move(journal, tmp_path / "aside" / "journal.jsonl")
    r = batch(s, t, out=fb)
    assert r.exit_code == 0, r.output
    lost = f"its session's journal {journal} is missing since the earlier fit"
    assert (
        f"{s}: skipped (finished earlier); {lost}: judged by its images' sizes and "
        "modification times, which match the fit" in said(r)
    ), r.output

    later(s / "linear" / "image_002.tif")
    r = batch(s, t, out=fb)
    assert r.exit_code == 0, r.output
    assert (
        f"{s}: refitted ({lost}; judged by its images' sizes and modification times: 1 of 6 "
        "images changed: image_002)" in said(r)
    ), r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_a_lost_journal_with_a_record_of_checksums_only_is_refitted_saying_so(
    tmp_path: Path,
) -> None:
    s, t, fb = fitted(tmp_path)
    summary_file = fb / "S" / "fit.json"
    summary = json.loads(summary_file.read_text(encoding="utf-8"))
    for image in summary["inputs"]["images"]:  # a record kept before sizes and times were
        image.pop("size"), image.pop("mtime_ns")
    summary_file.write_text(json.dumps(summary), encoding="utf-8")
    (s / "journal.jsonl").unlink()
    r = batch(s, t, out=fb)
    assert r.exit_code == 0, r.output
    assert (
        f"{s}: refitted (its session's journal {s / 'journal.jsonl'} is missing since the "
        "earlier fit, and the earlier fit's record names its images by that journal's "
        "checksums only, so whether they changed cannot be told: refitted)" in said(r)
    ), r.output


def counting_reads(monkeypatch: pytest.MonkeyPatch) -> list[Path]:
    """The files the next batches read whole, to hash or to decode their pixels, each batch
    as a new ``rti-rig`` process (what this one hashed is forgotten before each)."""
    import tifffile

    from rti_rig.app.usecases import fit_batch
    from rti_rig.runtime import session as session_module

    read: list[Path] = []
    real_prepare = fit_batch.prepare_batch

    def prepare(*args: Any, **kwargs: Any) -> Any:  # a batch begins
        monkeypatch.setattr(session_module, "_KNOWN_DIGESTS", {})
        return real_prepare(*args, **kwargs)

    monkeypatch.setattr(fit_batch, "prepare_batch", prepare)
    real_digest, real_imread = hashlib.file_digest, tifffile.imread

    def counted(fh: Any, digest: Any) -> Any:
        read.append(Path(fh.name))
        return real_digest(fh, digest)

    def imread(path: Any, *args: Any, **kwargs: Any) -> Any:
        read.append(Path(path))
        return real_imread(path, *args, **kwargs)

    monkeypatch.setattr(hashlib, "file_digest", counted)
    monkeypatch.setattr(tifffile, "imread", imread)
    return read


@pytest.mark.e2e
@pytest.mark.slow
def test_an_image_resaved_with_its_pixels_then_touched_stands(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A TIFF re-saved with zlib (other bytes, the same pixels) and then touched had been
    refitted after every touch: "1 of 6 images changed on disk since their capture"."""
    import tifffile

    s, t, fb = fitted(tmp_path)
    tif = s / "linear" / "image_002.tif"
    tifffile.imwrite(tif, tifffile.imread(tif), compression="zlib")
    for _ in range(2):  # re-saved, then touched, and again: the fit read these very pixels
        r = batch(s, t, out=fb)
        assert r.exit_code == 0, r.output
        assert said(r).count("skipped (finished earlier)") == 2, r.output
        later(tif)
    read = counting_reads(monkeypatch)
    r = batch(s, t, out=fb)
    assert said(r).count("skipped (finished earlier)") == 2, r.output
    assert read == [tif]  # its hash is the one recorded for it: its pixels are not decoded

    tifffile.imwrite(tif, tifffile.imread(tif) // 2, compression="zlib")  # an edit
    r = batch(s, t, out=fb)
    assert f"{s}: refitted (its session changed since the earlier fit: 1 of 6 images " in (
        said(r)
    ), r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_a_session_copied_without_its_times_is_read_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A session copied without its timestamps (``cp -r``) had been read in full on every
    batch: a hash that confirms an image now brings the fit's record of it up to date."""
    s, t, fb = fitted(tmp_path)
    moved = tmp_path / "copy" / "S"
    shutil.copytree(s, moved, copy_function=shutil.copyfile)  # new modification times
    shutil.rmtree(s)
    for image in (moved / "linear").glob("*.tif"):
        later(image)  # a copy made within the same tick as the session must differ too
    read = counting_reads(monkeypatch)
    r = batch(moved, t, out=fb)
    assert r.exit_code == 0 and said(r).count("skipped (finished earlier)") == 2, r.output
    assert len(read) == 6, read  # each image read once, to hash it
    read.clear()
    summary = json.loads((fb / "S" / "fit.json").read_text(encoding="utf-8"))
    assert summary["model"] == "ps" and len(summary["inputs"]["images"]) == 6  # kept whole
    r = batch(moved, t, out=fb)
    assert said(r).count("skipped (finished earlier)") == 2, r.output
    assert read == []
    assert [p.name for p in (fb / "S").iterdir() if p.name.startswith(".")] == []


@pytest.mark.e2e
@pytest.mark.slow
def test_judging_an_earlier_fit_writes_nothing_and_a_batch_keeps_its_update_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``earlier_fit`` is a question: it had rewritten fit.json itself, from whichever of a
    batch's up to three askers of a session came first. The update it found is returned, and
    the batch keeps it once."""
    from rti_rig.app.usecases import fit_batch

    s, t, fb = fitted(tmp_path)
    for image in (s / "linear").glob("*.tif"):
        later(image)  # new times, the same bytes: a hash confirms them
    fit_json = fb / "S" / "fit.json"
    before = fit_json.read_bytes()
    earlier = fit_batch.earlier_fit(fb / "S", s)
    assert earlier.stands and earlier.confirmed is not None
    assert fit_json.read_bytes() == before  # asked, not written

    kept: list[Path] = []
    real = fit_batch._keep_record

    def counted(path: Path, summary: Any, record: Any) -> None:
        kept.append(path)
        real(path, summary, record)

    monkeypatch.setattr(fit_batch, "_keep_record", counted)
    r = batch(s, t, out=fb)
    assert r.exit_code == 0 and said(r).count("skipped (finished earlier)") == 2, r.output
    assert kept == [fit_json]
    assert fit_batch.earlier_fit(fb / "S", s).confirmed is None  # the record is up to date


@pytest.mark.e2e
@pytest.mark.slow
def test_a_batch_judges_each_standing_earlier_fit_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A session is judged once, at its turn (fit_one): the batch had judged it too when it
    batch began (its record read, its images stat-ed or hashed), and fit_one again."""
    from rti_rig.app.usecases import fit_batch

    s, t, fb = fitted(tmp_path)
    asked: list[Path] = []
    real = fit_batch.earlier_fit

    def counted(final: Path, source: Path) -> Any:
        asked.append(source)
        return real(final, source)

    monkeypatch.setattr(fit_batch, "earlier_fit", counted)
    r = batch(s, t, out=fb)
    assert r.exit_code == 0 and said(r).count("skipped (finished earlier)") == 2, r.output
    assert sorted(asked) == [s, t]
