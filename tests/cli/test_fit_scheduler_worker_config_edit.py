"""`rti-rig fit --scheduler` on a worker whose installed rig config (a ``.toml`` of the package,
not code) was edited after the worker imported rti-rig: the worker is still trusted and fits.

Why: a worker's code was fingerprinted over its ``.py``, ``.toml`` and ``.lp`` files alike, and
a file changed since the worker's first check made it "another code, restart it": an edited
shipped config would have had every running worker refused, though a config is read when used
and the code the worker holds is its ``.py`` files alone."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest
from test_fit_scheduler_plugin import _fit, _one_worker_of

import rti_rig
from rti_rig import rig_configs

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

EDITED = "simulated_dome.toml"


def _installed_copy(where: Path) -> Path:
    """This rti-rig laid out as a wheel installs it (the rig configs inside ``rti_rig/``), with
    one shipped config differing by a comment: the worker imports it so."""
    package = where / "rti_rig"
    shutil.copytree(
        Path(rti_rig.__file__).parent, package, ignore=shutil.ignore_patterns("__pycache__")
    )
    configs = Path(rig_configs.__file__).parent
    shutil.copytree(configs, package / "rig_configs", ignore=shutil.ignore_patterns("__pycache__"))
    edited = package / "rig_configs" / EDITED
    edited.write_text(edited.read_text(encoding="utf-8") + "# before the edit\n", "utf-8")
    return where


#: Where the process it is evaluated in finds rti-rig's rig configs (an expression: a function
#: of this test module would need the module on the worker)
CONFIGS_FILE = "__import__('rti_rig.rig_configs', fromlist=['_']).__file__"


@pytest.mark.slow
def test_a_worker_whose_rig_config_was_edited_after_it_imported_rti_rig_still_fits(
    tmp_path: Path,
) -> None:
    session = make_session(tmp_path / "S", size=(24, 32))[0]
    where = _installed_copy(tmp_path / "installed")
    mine = Path(rig_configs.__file__).parent / EDITED
    out = tmp_path / "FIT"
    from distributed import Client

    with _one_worker_of(where) as cluster:
        with Client(cluster.scheduler_address, set_as_default=False) as client:
            (loaded,) = client.run(exec, "import rti_rig.app.usecases.fit_batch").values()
            assert loaded is None
            (configs,) = client.run(eval, CONFIGS_FILE).values()
        assert Path(configs).parent == where / "rti_rig" / "rig_configs"  # its own copy
        shutil.copyfile(mine, where / "rti_rig" / "rig_configs" / EDITED)  # the edit
        r = _fit(session, out, cluster.scheduler_address)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "source changed" not in said and "restart" not in said, said
    assert (out / "fit.json").is_file(), said
