"""Camera kinds: the registry that maps a rig config's ``[camera.device] kind`` to a driver.

A kind is its settings model (validated from the config table) and a builder that makes the
driver from those settings and what the composition root knows of the session
(:class:`CameraContext`). Adding a camera is one new module — settings, driver, one
:func:`register_camera_kind` call — and its module name in :data:`BUILTIN_MODULES` (or an
import before the rig config is loaded); docs/extending.md has a worked example.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from rti_rig.core.clock import Clock
from rti_rig.core.devices import Camera

#: Modules whose import registers the built-in kinds.
BUILTIN_MODULES = ("rti_rig.drivers.cameras.factory",)


@dataclass(frozen=True)
class CameraContext:
    """What a camera may need besides its settings, from the composition root."""

    clock: Clock | None = None
    #: Where a tethered camera's downloads go (the session's ``raw/.incoming``).
    output_dir: Path | None = None
    #: Fires the camera from elsewhere (the dome's shutter line), for a watched folder.
    trigger: Callable[[float], None] | None = None
    #: python-gphoto2's module, replaced at its API boundary in tests.
    gp_module: Any = None


@dataclass(frozen=True)
class CameraKind:
    name: str
    settings: type[BaseModel]
    build: Callable[[Any, CameraContext], Camera]
    #: Whether the driver sets the exposure it is asked for. A camera that only delivers files
    #: (a watched folder: the camera or its own program sets the shutter) cannot be metered:
    #: ``--auto-exposure`` is refused for it instead of asking for exposures it cannot take.
    sets_exposure: bool = True
    #: Whether its driver says when its exposure is over (an
    #: :class:`~rti_rig.core.devices.ExposingCamera`): the controller switches the LED off
    #: then, before the download. One that cannot say holds its LED lit until its frame is in,
    #: which the config's check against ``max_on_s`` counts (a list of kind names there had
    #: been a second answer to this, beside the controller's own look at the driver).
    says_exposure_end: bool = False


_KINDS: dict[str, CameraKind] = {}


def register_camera_kind(kind: CameraKind) -> CameraKind:
    """Make ``kind`` available as ``[camera.device] kind = "NAME"``; a name is registered once."""
    if kind.name in _KINDS and _KINDS[kind.name] is not kind:
        raise ValueError(f"a camera kind named {kind.name!r} is already registered")
    _KINDS[kind.name] = kind
    return kind


def _load_builtins() -> None:
    for module in BUILTIN_MODULES:
        importlib.import_module(module)


def camera_kind_names() -> tuple[str, ...]:
    _load_builtins()
    return tuple(_KINDS)


def camera_kind(name: object) -> CameraKind | None:
    """The kind called ``name``, or None."""
    _load_builtins()
    return _KINDS.get(name) if isinstance(name, str) else None
