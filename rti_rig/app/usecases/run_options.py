"""The words of ``rti-rig run``'s layout options (adaptive, elevation band), as the commands
rti-rig advises repeat them.

Why a module of its own: an adaptive refusal's advised command
(:mod:`rti_rig.app.usecases.adaptive`), a refused replay resume's new-session command
(:mod:`rti_rig.app.usecases.replay_advice`) and a resume refused as another request
(:mod:`rti_rig.app.usecases.resume_request`) each spelled these options out, one way each; a
command the user pastes must read the same whichever advice printed it. (A planned run's
``--lights N`` with its band is :func:`rti_rig.planner.uniform.band_run_options`.)
"""

from __future__ import annotations

from pathlib import Path

from rti_rig.core.shell_words import shell_word

#: The ``--until-error`` (degrees) a hint gives a user who gave none: the target the guide
#: (docs/guide.md §10) and the README show. Why a value: "add --until-error DEG" pasted was
#: refused as not a number; no session has estimated anything yet when it is advised.
HINT_UNTIL_ERROR_DEG = 2.0


def run_words(rig_config: Path, out_dir: Path) -> str:
    """``rti-rig run CONFIG --out OUT``, each a shell word (an advised command's start, the
    run's own ``--out``: nothing has been written to it when a request is refused)."""
    return f"rti-rig run {shell_word(str(rig_config))} --out {shell_word(str(out_dir))}"


def adaptive_options(
    until_error_deg: float | None,
    lights: int | None,
    min_lights: int | None,
    objective: str = "normals",
) -> str:
    """An adaptive session's own options, as an advised command repeats them
    (``--adaptive --lights 6``, ``--until-error 2 --min-lights 8 --objective relight``), the
    objective only where not the default (``--until-error`` is adaptive by itself)."""
    words = f"--until-error {until_error_deg:g}" if until_error_deg is not None else "--adaptive"
    words += f" --lights {lights}" if lights is not None else ""
    words += f" --min-lights {min_lights}" if min_lights is not None else ""
    return words + (f" --objective {objective}" if objective != "normals" else "")


def band_options(band: tuple[float, float]) -> str:
    """`` --min-elevation-deg A --max-elevation-deg B`` for those of ``band`` not at their
    defaults (nothing for every elevation)."""
    lo, hi = band
    return (f" --min-elevation-deg {lo:g}" if lo != 0.0 else "") + (
        f" --max-elevation-deg {hi:g}" if hi != 90.0 else ""
    )
