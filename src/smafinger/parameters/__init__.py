"""Named parameter sets, TOML files and overrides.

>>> from smafinger.parameters import get
>>> p = get("paper2010")
>>> p.h0_heating_W_m2K
20.0
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Callable

from . import authors2020, linear_bias_spring, paper2010
from .base import ParameterSet, field_spec, parse_value
from .errors import ParameterError
from .files import from_dict as _from_dict
from .files import load_toml as _load_toml
from .mechanisms import MECHANISMS, JointParameters, LinearActuatorParameters
from .options import ModelOptions

REGISTRY: dict[str, Callable[[], ParameterSet]] = {
    "paper2010": paper2010.parameters,
    "paper2010-table2": paper2010.table2,
    "authors2020": authors2020.parameters,
    "linear-bias-spring": linear_bias_spring.parameters,
}


def names() -> list[str]:
    return sorted(REGISTRY)


def get(name: str) -> ParameterSet:
    """A named parameter set."""
    if not isinstance(name, str) or name not in REGISTRY:
        raise ParameterError(f"unknown parameter set {name!r} (known: {', '.join(names())})")
    return REGISTRY[name]()


def changed_from_named(p: ParameterSet) -> tuple[str, ...]:
    """The fields and options where ``p`` differs from the named set it is called by (a set
    changed with ``--set`` or in a file keeps its base's name); () if no set has its name."""
    named = _named(p.name) if p.name in REGISTRY else None
    if named is None or type(named) is not type(p) or named == p:
        return ()
    values, options = vars(named), vars(named.options)  # frozen dataclasses: their fields
    return (tuple(k for k, v in vars(p).items() if k not in ("name", "source", "options") and v != values[k])
            + tuple(k for k, v in vars(p.options).items() if v != options[k]))


def is_named(p: ParameterSet) -> bool:
    """Whether ``p`` is a named set as registered (not changed with ``--set`` or in a file)."""
    return p.name in REGISTRY and _named(p.name) == p


@functools.cache
def _named(name: str) -> ParameterSet:
    """A named set, built once (about 0.1 ms; a sweep's summary asks every run; sets are frozen)."""
    return get(name)


def load_toml(path: str | Path, registry_get: Callable[[str], ParameterSet] = get) -> ParameterSet:
    """A set from a TOML file (``base = "NAME"`` starts from a named set)."""
    return _load_toml(path, registry_get)


def from_dict(data: dict, record: bool = False) -> ParameterSet:
    """A set from plain values (``to_dict`` plus ``mechanism``, or a parameter file's table);
    ``record``: a run's record, kept as it ran (:func:`.files.from_dict`)."""
    return _from_dict(data, get, record)


def resolve(spec: str | Path | ParameterSet) -> ParameterSet:
    """A set from a name, a TOML path, or a set."""
    if isinstance(spec, ParameterSet):
        return spec
    s = str(spec)
    if s in REGISTRY:
        return get(s)
    if s.endswith(".toml") or Path(s).exists():
        return load_toml(s)
    raise ParameterError(f"unknown parameter set {s!r} (known: {', '.join(names())}, or a .toml file)")


__all__ = ["ParameterError", "ParameterSet", "JointParameters", "LinearActuatorParameters", "ModelOptions",
           "MECHANISMS", "get", "names", "changed_from_named", "is_named", "resolve", "load_toml", "from_dict", "field_spec",
           "parse_value", "REGISTRY"]
