"""Checks on the files a command is asked to write, made before any work is done."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from rti_rig.app.config import LoadedRig
from rti_rig.core.errors import RtiRigError
from rti_rig.core.lp_format import image_paths, read_lp
from rti_rig.core.out_folders import ensure_file_writable
from rti_rig.core.shell_words import shown_path
from rti_rig.runtime.session import LP_NAME, MANIFEST


def rig_inputs(rig: Path, loaded: LoadedRig) -> dict[str, Path | None]:
    """The files a loaded rig config makes a command read: the config itself, a dome's LED
    calibration ``.lp`` (``lp_file``), its LED intensity correction
    (``intensity_correction_file``) and its LED map (``led_map_file``). Why: an ``--out
    --force`` onto one of them had replaced it with the command's output (a light
    calibration's TOML over the LED ``.lp``, a plan over the intensity correction), after
    which every command on that rig was refused at load. A replay rig (a recorded
    acquisition's ``.lp``) reads its recorded images too: ``plan --rig ACQ/dirs.lp --out
    ACQ/image_011.jpg --force`` had written the plan over a recorded image. An emulated
    dome's ``led_directions_file`` too (``lights-from-sphere --out`` onto the shipped
    example_dome_48.lp had replaced the rehearsal's truth with its measurement)."""
    inputs: dict[str, Path | None] = {"RIG": rig}
    dome = loaded.config.dome
    if dome is None:
        return inputs
    real = loaded.config.emulator.led_directions_file
    if real is not None:  # where the emulated LEDs really are: a rehearsal's truth
        inputs["emulated dome's LED directions (emulator.led_directions_file)"] = (
            loaded.folder / real
        )
    if dome.lp_file:
        inputs["rig's LED calibration (lp_file)"] = loaded.folder / dome.lp_file
        if loaded.config.backend == "replay":
            inputs.update(recorded_images(loaded.folder / dome.lp_file))
    serial = (loaded.raw.get("dome") or {}).get("serial") or {}
    name = serial.get("intensity_correction_file")
    if isinstance(name, str) and name:  # relative to the config's real folder, as it is read
        inputs["rig's LED intensity correction (intensity_correction_file)"] = (
            Path(loaded.path).resolve().parent / name
        )
    if dome.serial is not None and dome.serial.led_map_file:
        inputs["rig's LED map (led_map_file)"] = Path(dome.serial.led_map_file)
    return inputs


def recorded_images(lp_file: Path) -> dict[str, Path | None]:
    """The images a recorded acquisition's ``.lp`` names, where a replay reads them, as inputs
    for :func:`check_output_file`; none if the ``.lp`` cannot be read (the command that reads
    it as its rig says why, in its own words)."""
    try:
        entries = read_lp(lp_file, upper_hemisphere=True)
        paths = image_paths(lp_file, entries)
    except (OSError, RtiRigError):
        return {}
    return {
        f"recorded image {e.name} of the rig's .lp": p for e, p in zip(entries, paths, strict=True)
    }


def check_output_file(
    out_file: Path, force: bool, inputs: Mapping[str, Path | None], option: str = "--out"
) -> None:
    """Refuse, before any work, an output the command could not write or should not replace.

    ``inputs`` names the files the command reads (``{"PREVIEW": path, ...}``): replacing one of
    them is refused even with ``force``, as is replacing a file inside a session folder —
    nothing already captured is ever overwritten. ``option`` is the flag that named the file.
    Its folder is proved to take a new file (the file is written as a temporary one renamed
    over it): a folder that cannot had been found only once the work was done.
    """
    if out_file.is_dir():
        raise RtiRigError(
            f"{option} {shown_path(out_file)} is a folder: give the name of the file to write"
        )
    parent = out_file.parent
    if not parent.is_dir() and parent.exists():  # "folder X does not exist" was said of a file
        raise RtiRigError(
            f"{option} {shown_path(out_file)}: {shown_path(parent)} is a file, not a folder; "
            "give the new file's name in a folder"
        )
    if not parent.is_dir():
        raise RtiRigError(
            f"{option} {shown_path(out_file)}: folder {shown_path(parent)} does not exist; create "
            "it first"
        )
    if not out_file.exists():
        ensure_file_writable(out_file, option)
        return
    for what, path in inputs.items():
        if path is not None and path.exists() and out_file.samefile(path):
            # a session's rig's files are not read by the command that writes beside them
            reads = "" if "session's" in what else " this command reads"
            raise RtiRigError(
                f"{option} {shown_path(out_file)} is the {what}{reads}; it is never replaced, "
                "even with --force: choose another"
            )
    for folder in out_file.resolve().parents:
        if (folder / MANIFEST).is_file():
            if _own_lp(out_file, folder):
                break  # the user's own .lp beside the images (no capture): --force replaces it
            raise RtiRigError(
                f"{option} {shown_path(out_file)} would replace a file of the session in "
                f"{shown_path(folder)}; a session's files are never overwritten: write it elsewhere"
            )
    if not out_file.is_file():
        # the file is written as a temporary one renamed over it: --force onto /dev/full said
        # "Planned 12 lights → /dev/full" and left a plan where the device had been
        raise RtiRigError(
            f"{option} {shown_path(out_file)} is not a regular file (a device, a pipe or a "
            "socket), which the file written would replace, even with --force; give the name "
            "of a file"
        )
    if not force:
        raise RtiRigError(f"{option} {shown_path(out_file)} exists; use --force to replace it")
    ensure_file_writable(out_file, option)


def _own_lp(out_file: Path, session: Path) -> bool:
    """Whether ``out_file`` is an ``.lp`` of the user's own at the top of ``session`` (one
    ``export-lp`` or ``plan`` wrote there), not one of the files the session keeps.

    Why: the guide has an exported ``.lp`` put in the session folder (tools read its image
    names beside it), and ``export-lp --out S/linear.lp --force`` after a resume was refused
    ("a session's files are never overwritten"), though ``--force`` says it overwrites and the
    file holds nothing captured; ``lights.lp``, which the session writes, stays refused."""
    return (
        out_file.suffix.lower() == ".lp"
        and out_file.name != LP_NAME
        and out_file.resolve().parent == session
    )


def lp_name_note(out_file: Path, *, run_reads_it: bool = False) -> str | None:
    """What to say of an ``.lp`` written under another name (``--out plan.txt``), None when it
    is named ``.lp``.

    Why: ``plan`` and ``export-lp`` wrote the format to any name without a word, and the tools
    that read it find it by its suffix: relight and RTIBuilder look for an ``.lp``, and
    ``rti-rig fit`` refuses any other file ("give a session folder or an .lp file").
    ``run_reads_it``: a plan, which ``run --plan`` reads whatever its name."""
    if out_file.suffix.lower() == ".lp":
        return None
    run = "rti-rig run --plan reads it as it is, but " if run_reads_it else ""
    named = out_file.with_suffix(".lp")
    # a rename onto a file that is there replaces it: said, as the advice had led to it
    taken = (
        f" ({named} exists: a rename replaces it, so move that one aside first or choose "
        "another name ending in .lp)"
        if named.exists()
        else ""
    )
    return (
        f"{shown_path(out_file)} holds light positions in the .lp format but is not named .lp: "
        f"{run}relight, RTIBuilder and rti-rig fit find an .lp by its name; name it {named} to use "
        f"it there{taken}"
    )


def session_rig_inputs(config: object) -> dict[str, Path | None]:
    """The files the rig config a session names reads (the config itself, its ``lp_file``,
    its intensity correction, its LED map), for :func:`check_output_file`: ``--out
    rig.toml --force`` had replaced the dome's config with the .lp, and the advice that
    followed told the user to edit "the dome's config", an .lp by then. The config alone
    when it cannot be loaded (moved, or broken: nothing here reads it)."""
    if not isinstance(config, str) or not config:
        return {}
    path = Path(config)
    try:
        from rti_rig.app.config import load_rig_config

        inputs = rig_inputs(path, load_rig_config(path))
    except (OSError, RtiRigError):
        inputs = {"RIG": path}
    # "the RIG this command reads" is said of a --rig given: these are the manifest's
    return {
        (
            "session's rig config"
            if k == "RIG"
            else k.replace("rig's", "session's rig's", 1)
            if "rig's" in k
            else f"{k} of the session's rig"
        ): p
        for k, p in inputs.items()
    }
