"""Benchmarks write the repository's committed figures only when their command line asks."""

from __future__ import annotations

import sys

from benchmarks import report


def test_a_section_is_written_only_with_write(tmp_path, monkeypatch, capsys):
    doc = tmp_path / "benchmarks.md"
    monkeypatch.setattr(sys, "argv", ["bench"])
    assert report.write_section("demo", "| a |", doc) is None
    assert not doc.exists()
    assert "rerun with --write" in capsys.readouterr().out
    monkeypatch.setattr(sys, "argv", ["bench", "--write"])
    assert report.write_section("demo", "| a |", doc) == doc
    assert "<!-- BEGIN demo -->\n| a |\n<!-- END demo -->" in doc.read_text(encoding="utf-8")


def test_positional_arguments_leave_write_out():
    assert report.positional_args(["48", "--write", "2"]) == ["48", "2"]
