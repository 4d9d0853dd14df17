"""benchmarks.ptm_normals_fallback writes its table into docs/ only when asked (--write)."""

from __future__ import annotations

import pytest

from benchmarks import ptm_normals_fallback


@pytest.mark.parametrize(("argv", "writes"), [([], False), (["--write"], True)])
def test_the_table_goes_into_the_docs_only_with_write(
    monkeypatch: pytest.MonkeyPatch, argv: list[str], writes: bool
) -> None:
    """Benchmarks print their figures and write them to docs/ only when asked: the script had
    parsed --write and rewritten docs/reconstruction.md on every run all the same."""
    written: list[str] = []
    monkeypatch.setattr(ptm_normals_fallback, "row", lambda scene, name: f"| {scene} | {name} |")
    monkeypatch.setattr(
        ptm_normals_fallback, "write_section", lambda name, md, doc: written.append(name)
    )
    md = ptm_normals_fallback.main(argv)
    assert "| scene | lights |" in md
    assert written == (["ptm_normals_fallback"] if writes else [])
