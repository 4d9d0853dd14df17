"""A validation error of a config table in the user's words: the full key and what is wrong.

Why here: the rig config loader (app) and a driver's own nested table (``[dome.serial.protocol]``
is validated by the LED dome driver's settings) must word the same slip the same way, and the
drivers may stand on the core alone. The functions read pydantic's error dicts, so the core
needs no pydantic import.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Sequence
from typing import Any, get_args

#: what every table says of a key it does not know
UNKNOWN_KEY = "unknown key (check its spelling and the table it is in)"


def key_of(loc: tuple[Any, ...]) -> str:
    """A pydantic location as the dotted TOML key a user wrote (``dome.rings[2].count``)."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def _models_in(annotation: Any) -> list[Any]:
    """The pydantic models an annotation holds (``Dome | None``, ``list[Ring]``), told by
    their ``model_fields`` (the core imports no pydantic)."""
    if isinstance(annotation, type) and hasattr(annotation, "model_fields"):
        return [annotation]
    return [m for arg in get_args(annotation) for m in _models_in(arg)]


def _table_models(model: Any, loc: tuple[Any, ...]) -> list[Any]:
    """The models of the table holding the key at pydantic location ``loc`` below ``model``
    (none where that table is no model's: a free dict such as ``[camera.device]``)."""
    models = [model]
    for part in loc[:-1]:
        if isinstance(part, int):
            continue  # an element of a list of tables: the list's annotation is its model's
        fields = [m.model_fields[part] for m in models if part in m.model_fields]
        models = [m for f in fields for m in _models_in(f.annotation)]
    return models


def table_keys(model: Any, loc: tuple[Any, ...]) -> list[str]:
    """The keys of the table holding the key at pydantic location ``loc`` below ``model``:
    what an unknown key there is compared with. Empty where that table is no model's (a free
    dict such as ``[camera.device]``, checked by its driver's own model)."""
    models = _table_models(model, loc)
    return sorted({f.alias or name for m in models for name, f in m.model_fields.items()})


def field_of(model: Any, loc: tuple[Any, ...]) -> Any:
    """The pydantic field (its ``FieldInfo``) at location ``loc`` below ``model``, None where
    no model holds it (a free dict's key, an element of a list)."""
    last = loc[-1] if loc else None
    if last is None or isinstance(last, int):
        return None
    found = [m.model_fields[last] for m in _table_models(model, loc) if last in m.model_fields]
    return found[0] if found else None


#: pydantic's bound errors, the constraint each names, and its words for a user
_BOUNDS = {
    "greater_than": ("gt", "more than"),
    "greater_than_equal": ("ge", "at least"),
    "less_than": ("lt", "less than"),
    "less_than_equal": ("le", "at most"),
}

#: each constraint's words, by its attribute (``gt`` → "more than")
_LIMIT_WORDS = dict(_BOUNDS.values())


def _number(v: Any) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def _bounds_text(err: Any, field: Any) -> str | None:
    """A bound error as the whole range the key takes ("must be more than 0 and at most 1"),
    the field's description after it when it has one. Why: pydantic's "Input should be greater
    than 0" named one end of the range, so a fix within it could be refused at the other."""
    if err["type"] not in _BOUNDS:
        return None
    limits = [
        (attr, getattr(m, attr))
        for m in getattr(field, "metadata", ())
        for attr in _LIMIT_WORDS
        if getattr(m, attr, None) is not None
    ]
    if not limits:
        attr = _BOUNDS[err["type"]][0]
        limits = [(attr, err.get("ctx", {}).get(attr))]
    said = " and ".join(f"{_LIMIT_WORDS[a]} {_number(v)}" for a, v in limits)
    about = getattr(field, "description", None)
    return f"must be {said} (got {err['input']!r})" + (f": {about}" if about else "")


def tables_with_key(model: Any, key: str, at: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
    """The tables below ``model`` (paths of field names, ``()`` for its own) that have a key
    ``key``, nearest first: where a key written in the wrong table belongs."""
    found: list[tuple[str, ...]] = []
    fields = getattr(model, "model_fields", {})
    if any((f.alias or name) == key for name, f in fields.items()):
        found.append(at)
    for name, f in fields.items():
        for sub in _models_in(f.annotation):
            if len(at) < 4:  # the config's tables nest 3 deep: no walk round a cycle
                found += tables_with_key(sub, key, (*at, f.alias or name))
    return sorted(dict.fromkeys(found), key=len)


def unknown_key_text(key: str, known: Iterable[str] = (), elsewhere: Sequence[str] = ()) -> str:
    """What an unknown ``key`` is told: the table it belongs to where it is a key of another
    (``elsewhere``, the tables' names), else the known key of its own table it is closest to.

    Why: "check its spelling" left the user to find the slip (``exposur_s``) and the key it
    stands for by reading the docs; the closest key is named where one is close. A key spelt
    right in the wrong table (``white_balance`` under ``[camera.device]``, whose place is
    ``[camera.device.decode]``) had been asked "did you mean 'shutter_tolerance'?"."""
    if elsewhere:
        where = " or ".join(f"[{t}]" for t in elsewhere)
        return (
            f"unknown key in this table; '{key}' is a key of {where}: did you mean to put it there?"
        )
    close = difflib.get_close_matches(key, list(known), n=1, cutoff=0.6)
    return UNKNOWN_KEY + (f"; did you mean '{close[0]}'?" if close else "")


def error_text(
    err: Any, known: Iterable[str] = (), model: Any = None, prefix: tuple[str, ...] = ()
) -> str:
    """One pydantic error in a user's words: what is wrong, the value given, and for a number
    where the driver wants the camera's own text (``iso = 100``), how to write it. ``known``:
    the keys of the table an unknown key was found in, the closest of them suggested;
    ``model``: the model validated, whose field's whole range a bound error says, and whose
    other tables an unknown key is looked for in; ``prefix``: that model's table in the file
    (``("camera", "device")``), to name them."""
    msg = str(err["msg"]).removeprefix("Value error, ")
    if err["type"] == "extra_forbidden":
        loc = tuple(str(p) for p in err.get("loc", ()) if not isinstance(p, int))
        last = loc[-1] if loc else ""
        here = loc[:-1]
        elsewhere = [
            ".".join((*prefix, *t))
            for t in (tables_with_key(model, last) if model is not None and last else [])
            if t != here and (prefix or t)  # the file's top level is no [table] to name
        ]
        return unknown_key_text(last, known, elsewhere)
    if err["type"] == "missing":
        # pydantic's "Field required" said nothing of what to write, nor where
        loc = [str(part) for part in err.get("loc", ()) if not isinstance(part, int)]
        where = f"under [{'.'.join(loc[:-1])}]" if len(loc) > 1 else "at the top of the file"
        return f"required, and not given: add a line {loc[-1] if loc else 'for it'} = … {where}"
    if err["type"] == "value_error" or "input" not in err:
        return msg
    bounded = _bounds_text(err, field_of(model, tuple(err["loc"])) if model else None)
    if bounded is not None:
        return bounded
    got = err["input"]
    if err["type"] == "string_type" and isinstance(got, int | float) and not isinstance(got, bool):
        return f'{msg} (got {got!r}: write it in quotes, "{got}", as the camera names it)'
    return f"{msg} (got {got!r})"
