"""Checks on the files a command is asked to write, made before any work is done."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from rti_rig.app.config import LoadedRig
from rti_rig.core.errors import RtiRigError
from rti_rig.runtime.session import MANIFEST


def rig_inputs(rig: Path, loaded: LoadedRig) -> dict[str, Path | None]:
    """The files a loaded rig config makes a command read: the config itself and a dome's LED
    calibration ``.lp`` (its ``lp_file``). Why: an ``--out --force`` onto that ``.lp`` had
    replaced the dome's LED directions with the command's output (a light calibration's
    TOML), and every later command on that rig was refused at load."""
    inputs: dict[str, Path | None] = {"RIG": rig}
    dome = loaded.config.dome
    if dome is not None and dome.lp_file:
        inputs["rig's LED calibration (lp_file)"] = loaded.folder / dome.lp_file
    return inputs


def check_output_file(
    out_file: Path, force: bool, inputs: Mapping[str, Path | None], option: str = "--out"
) -> None:
    """Refuse, before any work, an output the command could not write or should not replace.

    ``inputs`` names the files the command reads (``{"PREVIEW": path, ...}``): replacing one of
    them is refused even with ``force``, as is replacing a file inside a session folder —
    nothing already captured is ever overwritten. ``option`` is the flag that named the file.
    """
    if out_file.is_dir():
        raise RtiRigError(f"{option} {out_file} is a folder: give the name of the file to write")
    parent = out_file.parent
    if not parent.is_dir():
        raise RtiRigError(f"{option} {out_file}: folder {parent} does not exist; create it first")
    if not out_file.exists():
        return
    for what, path in inputs.items():
        if path is not None and path.exists() and out_file.samefile(path):
            raise RtiRigError(
                f"{option} {out_file} is the {what} this command reads; choose another"
            )
    for folder in out_file.resolve().parents:
        if (folder / MANIFEST).is_file():
            raise RtiRigError(
                f"{option} {out_file} would replace a file of the session in {folder}; a "
                "session's files are never overwritten: write it elsewhere"
            )
    if not force:
        raise RtiRigError(f"{option} {out_file} exists; use --force to replace it")
