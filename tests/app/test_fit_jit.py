"""`rti-rig fit` and robust photometric stereo's compiled kernel (numba): imported only by a
robust fit (a least-squares fit's memory is at relight's limit), and a kernel numba cannot
cache (a read-only install without a writable home) still fits, its warning kept out of
``fit.json``."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

#: Fits a session through the CLI in a fresh process, then prints the JIT modules it loaded
#: (the command's own output, warnings included, to stderr).
_FIT_AND_LIST = (
    "import sys\n"
    "from typer.testing import CliRunner\n"
    "from rti_rig.cli import app\n"
    "r = CliRunner().invoke(app, ['fit', sys.argv[1], '--out', sys.argv[2], '--model',"
    " sys.argv[3], '--no-qa', '--no-ptm', '--no-hsh'])\n"
    "assert r.exit_code == 0, r.output\n"
    "print(r.output, file=sys.stderr)\n"
    "print(sorted(m for m in ('numba', 'llvmlite') if m in sys.modules))\n"
)


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_session(tmp_path_factory.mktemp("jit") / "s", size=(48, 64))[0]


def _fit(session: Path, out: Path, model: str, env: dict[str, str] | None = None):
    return subprocess.run(
        [sys.executable, "-c", _FIT_AND_LIST, str(session), str(out), model],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )


@pytest.mark.slow
def test_only_a_robust_fit_imports_numba(session: Path, tmp_path: Path) -> None:
    assert _fit(session, tmp_path / "ps", "ps").stdout.strip() == "[]"
    robust = _fit(session, tmp_path / "robust", "robust-ps").stdout.strip()
    assert robust == "['llvmlite', 'numba']"  # the check can fail


@pytest.mark.slow
def test_a_kernel_numba_cannot_cache_still_fits_and_fit_json_stays_clean(
    session: Path, tmp_path: Path
) -> None:
    """No cache locator applies (as with a read-only install and no writable home): the
    kernel is compiled in the process, a NumbaWarning says so on stderr, not in fit.json."""
    env = dict(os.environ, NUMBA_CACHE_LOCATOR_CLASSES="ZipCacheLocator")
    out = tmp_path / "out"
    done = _fit(session, out, "robust-ps", env)
    assert "compiled in every process" in done.stderr
    summary = json.loads((out / "fit.json").read_text())
    assert not any("numba" in w or "compiled" in w for w in summary["warnings"])
    cached = _fit(session, tmp_path / "cached", "robust-ps")  # the usual, cached kernel
    assert (out / "normals.npy").read_bytes() == (tmp_path / "cached" / "normals.npy").read_bytes()
    assert "compiled in every process" not in cached.stderr


def test_jit_warnings_are_left_out_of_the_fit_report() -> None:
    from numba.core.errors import NumbaPerformanceWarning, NumbaWarning

    from rti_rig.app.usecases.fit_bands import fit_warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.warn("cannot cache", NumbaWarning, stacklevel=1)
        warnings.warn("slow", NumbaPerformanceWarning, stacklevel=1)
        warnings.warn("about the fit", UserWarning, stacklevel=1)
    with warnings.catch_warnings(record=True) as reissued:
        warnings.simplefilter("always")
        kept = fit_warnings(caught)
    assert [str(w.message) for w in kept] == ["about the fit"]
    assert [str(w.message) for w in reissued] == ["cannot cache", "slow"]
