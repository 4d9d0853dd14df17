"""The ``rti-rig run`` command that starts a new session in place of a replay session whose
resume is refused, with the options that session began with.

Why: a replay session (``rti-rig run ACQ/dirs.lp``) whose acquisition changed, or is read
otherwise since, cannot be resumed, and its advice said to start a new session with
``rti-rig run ACQ/dirs.lp --out NEW``, "with the --lights and plan options this one began
with": a command that, pasted as printed, shot every light of the acquisition in place of the
session's 8, or a homogeneous layout in place of its plan or adaptive choice. The manifest
records what the session was asked for; the command repeats it.
"""

from __future__ import annotations

import shlex
from pathlib import Path
from typing import Any

from rti_rig.app.usecases.run_options import adaptive_options, band_options
from rti_rig.core.out_folders import free_folder_beside
from rti_rig.core.shell_words import shell_word


def new_session_dir(session_dir: Path | str) -> Path:
    """A folder beside ``session_dir`` that does not exist yet (``S-new``, ``S-new-2``...), for
    the new session a refused resume is told to start: never the session's own folder, whose
    images nothing may overwrite. A session given as ``.`` is named from its absolute path
    (:func:`~rti_rig.core.out_folders.free_folder_beside`; its own loop here had ended a
    ``run --resume .`` in "unexpected ValueError: PosixPath('.') has an empty name")."""
    return free_folder_beside(Path(session_dir), "new")


def allowed_no_normals(manifest: dict[str, Any], provenance: dict[str, Any]) -> bool:
    """Whether the session was run with ``--allow-no-normals``: as its provenance records it,
    or, in a manifest from before that record, as the note the flag's lights were captured
    with says (kept in its ``input_notes``).

    Why: every session begun before the record was told to start a new one without the flag,
    and that command, pasted as printed, was refused the very lights the session had been
    allowed. The note is written exactly when the flag let undetermined lights through, the
    one case the new session needs it; a session whose lights needed no flag needs none."""
    from rti_rig.app.normals_determined import CAPTURED_WITHOUT_NORMALS

    if "allow_no_normals" in provenance:
        return provenance["allow_no_normals"] is True
    notes = manifest.get("input_notes") or []
    return any(CAPTURED_WITHOUT_NORMALS in str(note) for note in notes)


def new_session_command(
    config_path: Path | str,
    manifest: dict[str, Any],
    session_dir: Path | str,
    most: int | None = None,
) -> str:
    """``rti-rig run CONFIG --out NEW`` with the session's layout options: its ``--plan``, its
    adaptive options (:func:`~rti_rig.app.usecases.run_options.adaptive_options`, ``--lights``
    only where it was given) or its homogeneous ``--lights N``, an elevation band other than
    0–90°, and ``--allow-no-normals`` (see :func:`allowed_no_normals`), each as the manifest
    recorded it. The plan is recorded as an absolute path, so the command runs from any folder
    (a manifest from before that record holds the path as it was typed, repeated as it is:
    where it was relative to is unknown). ``most``: the lights ``config_path`` has, where it
    is another acquisition than the session's: a count above them is advised as them (a
    command with the session's --lights 12 had been advised for an acquisition of 11, and was
    refused when run)."""
    words = [
        "rti-rig run",
        shell_word(str(config_path)),
        "--out",
        shell_word(str(new_session_dir(session_dir))),
    ]
    return " ".join(words) + session_options(manifest, most)


def session_options(manifest: dict[str, Any], most: int | None = None) -> str:
    """`` --lights 8``, `` --plan P``, `` --adaptive --lights 6 …``: the layout options the
    session of ``manifest`` began with, as :func:`new_session_command` repeats them (and a
    resume given other options says them); ``most`` caps their counts
    (:func:`new_session_command`)."""

    def capped(n: int) -> int:
        return n if most is None else min(n, most)

    words = [""]
    schedule = manifest.get("schedule") or {}
    provenance = schedule.get("provenance") or {}
    adaptive = manifest.get("adaptive")
    band: dict[str, Any] = {}  # the record that holds the elevation band, if any
    if isinstance(adaptive, dict):
        until = adaptive.get("until_error_deg")
        from rti_rig.app.usecases.adaptive import lights_asked

        lights, floor = lights_asked(adaptive), adaptive.get("min_lights")
        words.append(
            adaptive_options(
                float(until) if until is not None else None,
                capped(int(lights)) if lights is not None else None,  # --lights was given
                capped(int(floor)) if floor is not None else None,
                # a word, not a path: shell_word's ``$'...'`` form is for names on disk
                shlex.quote(str(adaptive.get("objective") or "normals")),
            )
        )
        band = adaptive
    elif provenance.get("plan_file"):
        words.append(f"--plan {shell_word(str(provenance['plan_file']))}")
    elif provenance.get("n") is not None:
        words.append(f"--lights {capped(int(provenance['n']))}")
        band = provenance
    if allowed_no_normals(manifest, provenance) and not isinstance(adaptive, dict):
        words.append("--allow-no-normals")
    low, high = band.get("min_elevation_deg"), band.get("max_elevation_deg")
    return " ".join(words) + band_options(
        (float(low) if low is not None else 0.0, float(high) if high is not None else 90.0)
    )
