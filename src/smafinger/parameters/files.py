"""Parameter files (TOML): one set per file, written and read back exactly.

Written here only: a whole set (:func:`to_toml`) or a named set with changes
(:func:`overrides_toml`).

A file names its mechanism (``mechanism = "joint"``; the default, for files written by
smafinger 0.1) and either gives every parameter or starts from a named set
(``base = "paper2010"``) and overrides some. Model options go in an ``[options]`` table (top-level
option keys, as smafinger 0.1 wrote them, are read too).
"""

from __future__ import annotations

import json
import tomllib
from dataclasses import fields
from pathlib import Path
from typing import Any, Callable

from .base import ParameterError, ParameterSet
from .mechanisms import MECHANISMS
from .options import OPTION_NAMES, ModelOptions


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):  # a TOML basic string: JSON's escapes are TOML's (control characters too)
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007f")
    return repr(float(v))


def to_toml(p: ParameterSet) -> str:
    """The set as TOML, every value with its doc as a comment."""
    lines = ["# smafinger parameter set (SI units; unit in each name)",
             f"mechanism = {_toml_value(p.mechanism)}"]
    for f in fields(p):
        if f.name == "options":
            continue
        lines.append(f"{f.name} = {_toml_value(getattr(p, f.name))}  # {f.metadata.get('doc', '')}".rstrip(" #"))
    lines += ["", "[options]"]
    for f in fields(p.options):
        v = getattr(p.options, f.name)
        lines.append(f"{f.name} = {_toml_value(v if isinstance(v, bool) else v.label)}  # {f.metadata['doc']}")
    return "\n".join(lines) + "\n"


def overrides_toml(base: str, changes: dict[str, Any], comment: str) -> str:
    """A parameter file starting from the named set ``base`` with ``changes`` (``name``,
    ``source``, fields, options), in the order given; ``comment`` is its first line."""
    lines = [f"# {comment}", f"base = {_toml_value(base)}"]
    lines += [f"{k} = {_toml_value(_plain(v))}" for k, v in changes.items()]
    return "\n".join(lines) + "\n"


def _plain(v: Any) -> Any:
    """A change as the file writes it: text and bools as given, an option by its label (a member
    was written as a float the loader refuses; found by an API fuzz), numbers as floats."""
    if isinstance(v, (bool, str)):
        return v
    return v.label if hasattr(v, "label") else float(v)


def load_toml(path: str | Path, registry_get: Callable[[str], ParameterSet]) -> ParameterSet:
    """Load a parameter file (see the module docstring)."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise ParameterError(f"parameter file not found: {path}") from None
    except (IsADirectoryError, PermissionError, UnicodeDecodeError) as exc:
        raise ParameterError(f"parameter file {path}: cannot be read ({type(exc).__name__})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{path}: not valid TOML ({exc})") from None
    try:
        return _from_dict(data, registry_get)
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from None


def from_dict(data: dict, registry_get: Callable[[str], ParameterSet], record: bool = False) -> ParameterSet:
    """A set from plain values, laid out as in a parameter file (``mechanism``, ``base``, the
    fields, options in an ``options`` table or at the top level, as ``to_dict`` gives them).
    ``record``: the values are a record of a set that ran (a run's provenance), kept as they
    are, where a file's edit of a value its options ignore is refused."""
    return _from_dict(data, registry_get, record)


def _from_dict(data: dict, registry_get: Callable[[str], ParameterSet], record: bool = False) -> ParameterSet:
    data = dict(data)
    base_name = data.pop("base", None)
    options = data.pop("options", {})
    if not isinstance(options, dict):
        raise ParameterError("options must be a table ([options])")
    top = {k: data.pop(k) for k in list(data) if k in OPTION_NAMES}
    twice = sorted(set(top) & set(options))
    if twice:  # one would silently win over the other
        k = twice[0]
        raise ParameterError(f"{k} is given twice, at the top level ({top[k]!r}) and in [options] ({options[k]!r}); "
                             "give it once")
    options = {**options, **top}
    unknown_opt = sorted(set(options) - set(OPTION_NAMES))
    if unknown_opt:
        raise ParameterError(f"unknown option(s) in [options]: {', '.join(unknown_opt)}")
    label = data.pop("mechanism", None)
    for key, value in (("base", base_name), ("mechanism", label)):
        if value is not None and not isinstance(value, str):
            raise ParameterError(f"{key} = {value!r} is not a string")
    if base_name is not None:
        try:
            base = registry_get(base_name)
        except ParameterError as exc:
            raise ParameterError(f"base = {base_name!r}: {exc}") from None
        if label is not None and label != base.mechanism:
            raise ParameterError(f"mechanism = {label!r} but base {base_name!r} is a {base.mechanism} set")
        return base.replace(**data, **options)
    label = label or "joint"
    if label not in MECHANISMS:
        raise ParameterError(f"mechanism = {label!r} is not one of {', '.join(MECHANISMS)}")
    cls = MECHANISMS[label]
    names = cls.field_names()
    unknown = sorted(set(data) - set(names))
    if unknown:
        raise ParameterError(f"unknown parameter(s) for a {label} set: {', '.join(unknown)}")
    missing = [m for m in sorted(set(names) - set(data)) if _required(cls, m)]
    if missing:
        raise ParameterError(f"missing parameter(s) {', '.join(missing)} (or give base = \"NAME\" of a named set)")
    missing_opt = sorted(set(OPTION_NAMES) - set(options))
    if missing_opt:
        raise ParameterError(f"missing option(s) {', '.join(missing_opt)} (or give base = \"NAME\" of a named set)")
    data.setdefault("name", "custom")
    data.setdefault("source", "user parameter file")
    p = cls(**data, options=ModelOptions(**options))
    if record:
        return p
    try:
        named = registry_get(p.name)
    except ParameterError:  # a set of the user's own
        return p
    if type(named) is cls and hasattr(p, "refuse_ignored_changes"):  # a named set's file, edited
        p.refuse_ignored_changes(named)
    return p


def _required(cls: type, name: str) -> bool:
    """A field with no default (``name`` and ``source`` get placeholders when missing)."""
    import dataclasses

    if name in ("name", "source"):
        return False
    f = next(f for f in fields(cls) if f.name == name)
    return f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
