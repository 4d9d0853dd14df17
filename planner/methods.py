"""Planning methods: what a method is, and the registry the planner looks methods up in.

A method turns the rig's usable lights (``candidates``), the homogeneous starting layouts and,
when there is one, the estimated surface into the indices of the lights to fire. The pipeline
around it (surface, objective, order, report) is the same for every method, so adding a method
is one new module that defines a :class:`PlanMethod` and calls :func:`register_method` (and, for
a built-in, its module's name in :data:`BUILTIN_MODULES`): ``--method NAME`` finds it, and the
checks, the error's list of choices and the report follow from the registry
(docs/extending.md).
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.errors import ScheduleError
from rti_rig.core.fit_minimums import PLAN_DEFAULT_LIGHTS

if TYPE_CHECKING:
    from rti_rig.planner.objectives import Candidates, NormalsObjective, RelightObjective
    from rti_rig.planner.plan_report import PlanReport
    from rti_rig.planner.surface_estimate import SurfaceEstimate

#: What a method needs of the object's surface:
#: ``none`` — nothing (a preview, if given, is evaluated for the report only, and a preview that
#: cannot be read is a note, not an error); ``flat`` — a surface, assumed level and matte (or
#: glossy if declared) when there is no preview; ``preview`` — a surface estimated from a
#: preview, which must be given.
SurfaceNeed = Literal["none", "flat", "preview"]

#: Modules whose import registers the built-in methods (in the order --help lists them).
BUILTIN_MODULES = ("rti_rig.planner.builtin_methods",)


@dataclass
class MethodContext:
    """What a method may use to choose lights (one planning request)."""

    n: int
    candidates: Candidates
    #: Homogeneous layouts as (label, candidate indices), the one at the user's floor first.
    starts: list[tuple[str, NDArray[np.intp]]]
    #: None when the method needs none and no preview was given.
    surface: SurfaceEstimate | None
    report: PlanReport
    seed: int
    material: str
    objective: str
    #: The elevation ceiling, and whether it cuts the rig's range above the floor.
    max_elevation_deg: float
    ceiling_cuts: bool
    #: whether ``--min-elevation-deg`` was typed, and the whole ``rti-rig plan`` command for
    #: an even layout of this rig (shell words, a free ``--out``; no floor where one was
    #: typed): advice offers only what the user did not choose, as a command that pastes
    min_elevation_given: bool = False
    uniform_said: str = ""


class PlanMethod(Protocol):
    """One way of choosing lights.

    ``prepare`` picks the lights before any objective exists (a clustering method finds its
    layout here and may add it to ``ctx.starts`` as a starting layout); it is always called.
    When there is a surface to score against, ``decide`` then returns the lights, given the
    objective, and records in ``ctx.report.expected`` the expected errors of the layouts it
    compared; without one (``surface == "none"`` and no preview) ``prepare``'s lights are
    planned as they are.
    """

    name: str
    #: One line for ``--help``.
    summary: str
    surface: SurfaceNeed
    #: Why a preview is needed (the error when ``surface == "preview"`` and none was given).
    needs_preview_reason: str
    #: Whether the chosen lights depend on the objective (else the objective only scores them).
    optimises_objective: bool

    def prepare(self, ctx: MethodContext) -> NDArray[np.intp]: ...

    def decide(
        self,
        ctx: MethodContext,
        objective: NormalsObjective | RelightObjective,
        chosen: NDArray[np.intp],
    ) -> NDArray[np.intp]: ...


_METHODS: dict[str, PlanMethod] = {}


def register_method(method: PlanMethod) -> PlanMethod:
    """Make ``method`` available by its name (``--method NAME``); a name is registered once."""
    if method.name in _METHODS and _METHODS[method.name] is not method:
        raise ValueError(f"a planning method named {method.name!r} is already registered")
    _METHODS[method.name] = method
    return method


def _load_builtins() -> None:
    for module in BUILTIN_MODULES:
        importlib.import_module(module)


def method_names() -> tuple[str, ...]:
    """The registered methods' names, built-ins first."""
    _load_builtins()
    return tuple(_METHODS)


def get_method(
    name: str, rig: str = "RIG.toml", out: str = "DIR", lights: int = PLAN_DEFAULT_LIGHTS
) -> PlanMethod:
    """The method called ``name``; an unknown name is refused with the known ones. ``rig``,
    ``out`` and ``lights``: the rig config as the user's command gave it, a folder for the run
    (shell words; the planner looks at no folder, its caller does) and a count, for the command
    the refusal offers (it had always said ``RIG.toml``, where the command line at hand named
    the config, and ``--lights N --out DIR``, which pasted was refused or made DIR)."""
    _load_builtins()
    try:
        return _METHODS[name]
    except KeyError:
        # "adaptive" is what a user who read docs/adaptive.md asks for: it is a way to run a
        # session, not a plan (each light is chosen from the images already captured), and
        # the bare refusal had not said where it is
        adaptive = (
            " (an adaptive session is not planned ahead: it chooses each next light from the "
            f"images captured so far; run it with rti-rig run {rig} --adaptive --lights {lights} "
            f"--out {out})"
            if name.strip().lower() == "adaptive"
            else ""
        )
        raise ScheduleError(
            f"--method {name!r} is not known; choose {', '.join(_METHODS)}{adaptive}"
        ) from None
