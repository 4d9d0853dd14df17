"""Paths handed to OpenCV's ``imread``/``imwrite``: the one place that knows which form each
OpenCV takes.

Why: OpenCV's Python binding turns a ``str`` into its C++ string through UTF-8. A name whose
bytes on disk are not UTF-8 (an archive unpacked with its Windows names) is, in Python, a
``str`` with a lone surrogate: the binding's conversion fails and older bindings go on with a
NULL pointer, a segmentation fault that ends the process with no word. Its bytes avoid that,
but only newer bindings take ``bytes``: OpenCV 4.8 (which ``pyproject.toml`` allows) refuses
them (``TypeError: Can't convert object to 'str' for 'filename'``), so bytes for every path
broke every image read and write there. So: a name that is UTF-8 is given as the ``str`` every
OpenCV takes; one that is not is given as bytes, and where this OpenCV refuses bytes the file
is read (``np.fromfile`` + ``cv2.imdecode``) or written (``cv2.imencode`` + ``tofile``) by
Python, whose file calls take any name.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import cv2
import numpy as np

#: What OpenCV's binding raises for an argument of a type it does not take (a plain call:
#: TypeError; an overloaded one: cv2.error "Overload resolution failed").
NOT_TAKEN = (TypeError, cv2.error)


def opencv_name(path: str | os.PathLike[str]) -> str | bytes:
    """``path`` as OpenCV is to be given it: a ``str`` where it is UTF-8 (every OpenCV takes
    it), else its bytes on disk (a ``str`` would crash the process; see the module's note)."""
    text = os.fsdecode(path)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return os.fsencode(text)
    return text


def imread(path: str | os.PathLike[str], flags: int = cv2.IMREAD_UNCHANGED) -> Any:
    """``cv2.imread(path, flags)`` for any name on disk: None where the file is missing or
    not an image OpenCV decodes, as ``cv2.imread`` says it."""
    name = opencv_name(path)
    if isinstance(name, str):
        return cv2.imread(name, flags)
    try:
        return cv2.imread(name, flags)
    except NOT_TAKEN:  # an OpenCV that takes no bytes: the file read by Python
        try:
            data = np.fromfile(name, np.uint8)
        except OSError:
            return None
        return cv2.imdecode(data, flags) if data.size else None


def imwrite(path: str | os.PathLike[str], image: Any, params: Sequence[int] = ()) -> bool:
    """``cv2.imwrite(path, image, params)`` for any name on disk: whether it was written, as
    ``cv2.imwrite`` says it (False, not an exception, for a folder that refuses the file)."""
    name = opencv_name(path)
    if isinstance(name, str):
        return bool(cv2.imwrite(name, image, list(params)))
    try:
        return bool(cv2.imwrite(name, image, list(params)))
    except NOT_TAKEN:  # an OpenCV that takes no bytes: encoded by it, written by Python
        ext = os.path.splitext(name)[1].decode("ascii", "replace") or ".png"
        ok, encoded = cv2.imencode(ext, image, list(params))
        if not ok:
            return False
        try:
            encoded.tofile(name)
        except OSError:
            return False
        return True
