"""Names of a package loaded on first use (PEP 562's module ``__getattr__``).

Why: importing one light module of a driver package (its settings, for a rig config) runs the
package's ``__init__``; if that imported the driver, its transport and the vendor library,
``rti-rig plan`` would load a serial stack it never uses. The package lists where each name
lives and loads it when first asked for; its ``TYPE_CHECKING`` block names the same imports so
that type checkers and the import-linter contracts still see the edges
(tests/architecture/test_lazy_packages.py keeps the two equal).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any


def lazy_getattr(
    package: str, where: dict[str, str], namespace: dict[str, Any]
) -> Callable[[str], Any]:
    """A module ``__getattr__`` for ``package`` that imports ``where[name]`` on first use and
    keeps the value in the package's ``namespace`` (later look-ups are plain attributes)."""

    def __getattr__(name: str) -> Any:
        if name in where:
            value = getattr(importlib.import_module(where[name]), name)
            namespace[name] = value
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
