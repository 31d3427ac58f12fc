"""Named parameter sets, TOML files and overrides.

>>> from smafinger.parameters import get
>>> p = get("paper2010")
>>> p.h0_heating_W_m2K
20.0
"""

from __future__ import annotations

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
    try:
        return REGISTRY[name]()
    except KeyError:
        raise ParameterError(
            f"unknown parameter set {name!r} (known: {', '.join(names())}, or a .toml file)"
        ) from None


def load_toml(path: str | Path, registry_get: Callable[[str], ParameterSet] = get) -> ParameterSet:
    """A set from a TOML file (``base = "NAME"`` starts from a named set)."""
    return _load_toml(path, registry_get)


def from_dict(data: dict) -> ParameterSet:
    """A set from plain values (``to_dict`` plus ``mechanism``, or a parameter file's table)."""
    return _from_dict(data, get)


def resolve(spec: str | Path | ParameterSet) -> ParameterSet:
    """A set from a name, a TOML path, or a set."""
    if isinstance(spec, ParameterSet):
        return spec
    s = str(spec)
    if s in REGISTRY:
        return get(s)
    if s.endswith(".toml") or Path(s).exists():
        return load_toml(s)
    return get(s)


__all__ = ["ParameterError", "ParameterSet", "JointParameters", "LinearActuatorParameters", "ModelOptions",
           "MECHANISMS", "get", "names", "resolve", "load_toml", "from_dict", "field_spec", "parse_value", "REGISTRY"]
