"""Benchmark scripts: each prints its figures and writes them to a section of docs/benchmarks.md."""
