"""Typed overrides of a scenario's run: parameter fields and run settings, checked once.

One object for every way a run is changed from its scenario: the scenario's own readings
(e.g. the paper's friction rule), the Fig. 15 investigation's readings, and ``--set
NAME=VALUE`` on the command line.

>>> from smafinger.paper.overrides import Overrides
>>> ov = Overrides.of(T_init_C=60, tol_deg=0.2)
>>> ov.params, ov.tol_deg
((('T_init_C', 60.0),), 0.2)
>>> Overrides.parse(["M_SF_Nm=0.02"]).then(ov).texts()
('M_SF_Nm=0.02', 'T_init_C=60.0')
"""

from __future__ import annotations

import dataclasses
import math
import typing
from dataclasses import dataclass
from typing import Any, Iterable

from ..parameters import MECHANISMS, ParameterError, ParameterSet
from ..parameters.base import parse_value
from ..parameters.options import OPTION_NAMES, OPTION_TYPES, parse_option
from ..values import is_real, one_or_many

#: run settings an override may change (``make_spec`` arguments), with their types
RUN_SETTINGS: dict[str, type] = {
    "strategy": str, "profile": str, "t_end_s": float, "tol_deg": float, "hold_s": float,
    "independent_wait": bool,
}


def _field_types() -> dict[str, type]:
    """Every mechanism's parameter fields with their types (options are checked by their enum)."""
    out: dict[str, type] = {}
    for cls in MECHANISMS.values():
        hints = typing.get_type_hints(cls)
        out.update({f.name: hints[f.name] for f in dataclasses.fields(cls) if f.name != "options"})
    return out


_FIELD_TYPES = _field_types()


def _check(name: str, value: Any, kind: type) -> Any:
    """``value`` as ``kind`` (an int is a float); ``ParameterError`` naming the field otherwise."""
    if kind is float:  # numpy's numbers too; an int beyond any float is not finite (found by an API fuzz)
        try:
            x = float(value) if is_real(value) else math.nan
        except OverflowError:
            x = math.inf
        if not math.isfinite(x):
            raise ParameterError(f"override {name} = {value!r:.40}: not a finite number")
        return x
    if not isinstance(value, kind):
        raise ParameterError(f"override {name} = {value!r}: not a {kind.__name__}")
    return value


def _text(value: Any) -> str:
    return ("true" if value else "false") if isinstance(value, bool) else str(value)


@dataclass(frozen=True)
class Overrides:
    """Parameter fields and run settings that replace a scenario's (``None``: unchanged).

    Build with :meth:`of` (Python values) or :meth:`parse` (``NAME=VALUE`` strings); both
    check every name and type. Values are range-checked by
    :class:`~smafinger.parameters.ParameterSet` when applied (:meth:`apply`).
    """

    params: tuple[tuple[str, Any], ...] = ()
    strategy: str | None = None
    profile: str | None = None
    t_end_s: float | None = None
    tol_deg: float | None = None
    hold_s: float | None = None
    independent_wait: bool | None = None

    @classmethod
    def of(cls, **changes: Any) -> "Overrides":
        """Overrides from keyword arguments: run settings (:data:`RUN_SETTINGS`) or
        parameter fields; ``ParameterError`` naming an unknown name or a wrong type."""
        params: dict[str, Any] = {}
        run: dict[str, Any] = {}
        for name, value in changes.items():
            if name in RUN_SETTINGS:
                run[name] = _check(name, value, RUN_SETTINGS[name])
            elif name in OPTION_TYPES:
                params[name] = parse_option(name, value)
            elif name in OPTION_NAMES:  # a boolean option
                params[name] = _check(name, value, bool)
            elif name in _FIELD_TYPES:
                params[name] = _check(name, value, _FIELD_TYPES[name])
            else:
                raise ParameterError(f"override {name} = {value!r}: unknown parameter or run setting")
        return cls(params=tuple(params.items()), **run)

    @classmethod
    def parse(cls, assignments: Iterable[str]) -> "Overrides":
        """Parameter overrides from ``NAME=VALUE`` strings (as given with ``--set``), each
        value parsed by the field's kind (:func:`smafinger.parameters.base.parse_value`)."""
        changes: dict[str, Any] = {}
        for a in assignments:
            if "=" not in a:
                raise ParameterError(f"override {a!r} is not of the form NAME=VALUE")
            name, raw = (s.strip() for s in a.split("=", 1))
            changes[name] = parse_value(name, raw)  # names an unknown parameter
        return cls.of(**changes)

    @classmethod
    def coerce(cls, value: "Overrides | Iterable[str] | None") -> "Overrides":
        """An :class:`Overrides` as is; ``NAME=VALUE`` strings parsed (one string is a list of one,
        :func:`smafinger.values.one_or_many`); ``None``: none."""
        if value is None:
            return cls()
        if isinstance(value, Overrides):
            return value
        return cls.parse(one_or_many(value))

    def then(self, other: "Overrides") -> "Overrides":
        """These overrides followed by ``other`` (``other`` wins where both set a value)."""
        params = dict(self.params)
        params.update(other.params)
        run = {k: getattr(other, k) if getattr(other, k) is not None else getattr(self, k)
               for k in RUN_SETTINGS}
        return Overrides(params=tuple(params.items()), **run)

    def apply(self, params: ParameterSet) -> ParameterSet:
        """``params`` with the parameter overrides applied (validated by the set)."""
        return params.replace(**dict(self.params)) if self.params else params

    def value(self, name: str, default: Any = None) -> Any:
        """The overridden value of parameter field ``name`` (``default`` if not overridden)."""
        return dict(self.params).get(name, default)

    def settings(self) -> dict[str, Any]:
        """The run settings that are set, as ``make_spec`` keyword arguments."""
        return {k: getattr(self, k) for k in RUN_SETTINGS if getattr(self, k) is not None}

    def texts(self) -> tuple[str, ...]:
        """Every override as a ``NAME=VALUE`` string (parameters, then run settings)."""
        items = list(self.params) + list(self.settings().items())
        return tuple(f"{k}={_text(v)}" for k, v in items)


__all__ = ["Overrides", "RUN_SETTINGS"]
