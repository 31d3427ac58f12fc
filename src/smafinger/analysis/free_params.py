"""The parameters a fit frees, their bounds, and the optimiser's unit box.

A fit names the fields of a parameter set to adjust, each with bounds (``--free NAME[:LO:HI]``;
defaults per mechanism in :data:`DEFAULT_FREE`). The optimisers work in the unit box [0, 1]^n:
coordinate u maps to LO + u (HI - LO), or geometrically for a positive range of a decade or
more (:attr:`FreeParameter.log`), so that every direction has the same scale.

Fields can be tied: ``--free static_friction_N+coulomb_friction_N`` fits one value given to both
(the slider's friction: with a static friction below the sliding one the model chatters instead
of sticking, and a static friction alone makes the stick-slip pattern, and so the misfit, jump
with every small change of the other parameters; tied, the misfit is smooth in the friction near
a small friction, but still rugged where the friction is large, see ``docs/identification.md``).

Transformation temperatures come in ordered pairs (A_S0 < A_F0, M_F0 < M_S0, and for a major
loop that is not empty M_F0 < A_S0, M_S0 < A_F0; a set with them the other way round is
invalid). When a pair member is free its range is narrowed to keep the
order by at least :data:`MIN_GAP_C`: the upper member maps onto [max(LO, lower + gap), HI], the
lower onto [LO, min(HI, upper - gap)] when the upper is held. Every point of the box is then a
valid, ordered set: the optimisers never meet a refusal there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from ..parameters import ParameterError, ParameterSet
from ..parameters.mechanisms import JointParameters, LinearActuatorParameters
from ..values import one_or_many

#: (lower, upper) fields that must stay ordered: each transformation's start and finish, and
#: the major loop not empty at zero stress (M_F0 < A_S0, M_S0 < A_F0: a set is refused otherwise)
ORDERED_PAIRS = (("A_S0_C", "A_F0_C"), ("M_F0_C", "M_S0_C"), ("M_F0_C", "A_S0_C"), ("M_S0_C", "A_F0_C"))
#: smallest width kept between the members of an ordered pair [degC]
MIN_GAP_C = 0.5


def _rank(name: str) -> int:
    """How many ordered pairs deep ``name`` sits (0: the lower member of every pair it is in)."""
    return max((1 + _rank(lower) for lower, upper in ORDERED_PAIRS if upper == name), default=0)


class FreeParameterError(ParameterError):
    """A ``--free`` option cannot be used (unknown field, bad bounds, start outside them)."""


@dataclass(frozen=True)
class BoundRule:
    """Default bounds of a field from its start value: ``start -+ shift``, ``start /* factor``, or ``span``."""

    name: str
    shift: float | None = None
    factor: float | None = None
    span: tuple[float, float] | None = None

    def bounds(self, start: float) -> tuple[float, float]:
        if self.span is not None:
            return self.span
        if self.shift is not None:
            return start - self.shift, start + self.shift
        return start / self.factor, start * self.factor


_TEMPERATURES = tuple(BoundRule(n, shift=15.0) for n in ("A_S0_C", "A_F0_C", "M_S0_C", "M_F0_C"))
#: the fields a fit frees by default, per mechanism: transformation temperatures, convection
#: (heating and cooling apart), recoverable strain, the spring's preload; for the joint also its
#: viscous friction while heating. Stick-slip friction (the slider's static and sliding friction,
#: the joint's M_SF) makes the misfit rugged: free it on purpose (``docs/identification.md``).
DEFAULT_FREE: dict[str, tuple[BoundRule, ...]] = {
    LinearActuatorParameters.mechanism: _TEMPERATURES + (
        BoundRule("h0_heating_W_m2K", factor=4.0), BoundRule("h0_cooling_W_m2K", factor=4.0),
        BoundRule("eps_R", factor=2.0), BoundRule("bias_spring_preload_N", factor=2.0)),
    JointParameters.mechanism: _TEMPERATURES + (
        BoundRule("h0_heating_W_m2K", factor=4.0), BoundRule("h0_cooling_W_m2K", factor=4.0),
        BoundRule("eps_R", factor=2.0), BoundRule("spring_length_lower_m", factor=1.3),
        BoundRule("C_DF_heating_Nms", factor=4.0)),
}
#: bounds of fields a fit does not free by default but is often asked to
OTHER_RULES = (BoundRule("static_friction_N+coulomb_friction_N", span=(0.0, 1.0)),
               BoundRule("static_friction_N", span=(0.0, 1.0)), BoundRule("coulomb_friction_N", span=(0.0, 1.0)),
               BoundRule("M_SF_Nm", span=(0.0, 0.05)), BoundRule("M_DF_Nm", span=(0.0, 0.05)))
#: default bounds of a field without a rule: start /* this factor
GENERIC_FACTOR = 4.0
#: joins tied fields in a free parameter's name
TIE = "+"


@dataclass(frozen=True)
class FreeParameter:
    """One fitted value: its bounds, whether it is searched in log scale, and the fields it sets
    (one, or several tied: ``name`` is then their names joined by ``+``)."""

    name: str
    lo: float
    hi: float
    log: bool = False

    @property
    def fields(self) -> tuple[str, ...]:
        return tuple(self.name.split(TIE))

    def from_unit(self, u: float, lo: float | None = None, hi: float | None = None) -> float:
        lo = self.lo if lo is None else lo
        hi = self.hi if hi is None else hi
        if self.log:
            return math.exp(math.log(lo) + u * (math.log(hi) - math.log(lo)))
        return lo + u * (hi - lo)

    def to_unit(self, v: float, lo: float | None = None, hi: float | None = None) -> float:
        lo = self.lo if lo is None else lo
        hi = self.hi if hi is None else hi
        if self.log:
            u = (math.log(v) - math.log(lo)) / (math.log(hi) - math.log(lo))
        else:
            u = (v - lo) / (hi - lo)
        return min(max(u, 0.0), 1.0)


def _float_fields(p: ParameterSet) -> dict[str, tuple[float, float]]:
    return {f.name: f.metadata["range"] for f in fields(p) if f.metadata.get("kind") == "float"}


def make_free(p: ParameterSet, name: str, lo: float | None = None, hi: float | None = None) -> FreeParameter:
    """A checked :class:`FreeParameter` of ``p`` (bounds: given, else the default rule).

    ``name`` is a field, or fields tied with ``+`` (they must start equal).
    """
    ranges = _float_fields(p)
    tied = name.split(TIE)
    for f in tied:
        if f not in ranges:
            raise FreeParameterError(f"--free {name}: {f!r} is not a numeric parameter of a {p.mechanism} set")
        if len(tied) > 1 and any(f in pair for pair in ORDERED_PAIRS):
            raise FreeParameterError(f"--free {name}: {f} cannot be tied to another field")
    if len(set(tied)) < len(tied):
        raise FreeParameterError(f"--free {name}: a field is named twice")
    starts = [float(getattr(p, f)) for f in tied]
    if len(set(starts)) > 1:
        raise FreeParameterError(f"--free {name}: tied fields start at different values "
                                 f"({', '.join(f'{f} = {v:g}' for f, v in zip(tied, starts))}); set them equal "
                                 f"with --set")
    start = starts[0]
    f_lo = max(ranges[f][0] for f in tied)
    f_hi = min(ranges[f][1] for f in tied)
    if lo is None:
        rules = [r for rs in DEFAULT_FREE.values() for r in rs] + list(OTHER_RULES)
        rule = next((r for r in rules if r.name == name), None)
        if rule is None:
            if start <= 0.0:
                raise FreeParameterError(f"--free {name}: the start value is {start:g}; give bounds, "
                                         f"--free {name}:LO:HI")
            rule = BoundRule(name, factor=GENERIC_FACTOR)
        lo, hi = rule.bounds(start)
        lo, hi = max(lo, f_lo), min(hi, f_hi)
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise FreeParameterError(f"--free {name}:{lo:g}:{hi:g}: the bounds must be finite with LO < HI")
    if lo < f_lo or hi > f_hi:
        raise FreeParameterError(f"--free {name}:{lo:g}:{hi:g}: outside the allowed range [{f_lo:g}, {f_hi:g}]")
    if not lo <= start <= hi:
        raise FreeParameterError(f"--free {name}:{lo:g}:{hi:g}: the start value {start:g} (from --params) is "
                                 f"outside the bounds")
    ordered = any(name in pair for pair in ORDERED_PAIRS)
    return FreeParameter(name, float(lo), float(hi), log=(not ordered and lo > 0.0 and hi / lo >= 10.0))


def parse_free(p: ParameterSet, options: list[str] | None) -> tuple[FreeParameter, ...]:
    """``--free NAME[:LO:HI]`` options (none: the mechanism's :data:`DEFAULT_FREE`)."""
    if not options:
        return tuple(make_free(p, r.name) for r in DEFAULT_FREE[p.mechanism])
    out: list[FreeParameter] = []
    for opt in one_or_many(options):  # one option is a list of one (it was read letter by letter)
        parts = [s.strip() for s in opt.split(":")]
        if len(parts) not in (1, 3) or not parts[0]:
            raise FreeParameterError(f"--free {opt!r}: expected NAME or NAME:LO:HI, e.g. A_S0_C:55:85")
        bounds = []
        for s in parts[1:]:
            try:
                bounds.append(float(s))
            except ValueError:
                raise FreeParameterError(f"--free {opt!r}: {s!r} is not a number") from None
        new = make_free(p, parts[0], *bounds)
        taken = {f for fp in out for f in fp.fields}
        if taken & set(new.fields):
            raise FreeParameterError(f"--free {opt!r}: {sorted(taken & set(new.fields))[0]} is freed twice")
        out.append(new)
    return tuple(out)


class FreeBox:
    """The map between the unit box [0, 1]^n and parameter sets (ordered pairs kept ordered)."""

    def __init__(self, base: ParameterSet, free: tuple[FreeParameter, ...]):
        if not free:
            raise FreeParameterError("no parameter to fit (give --free NAME, or leave it out for the defaults)")
        self.base, self.free = base, tuple(free)
        self.names = tuple(f.name for f in free)
        self._index = {n: i for i, n in enumerate(self.names)}
        for lower, upper in ORDERED_PAIRS:
            self._check_pair(lower, upper)

    @property
    def n(self) -> int:
        return len(self.free)

    def _check_pair(self, lower: str, upper: str) -> None:
        il, iu = self._index.get(lower), self._index.get(upper)
        if il is None and iu is None:
            return
        lo_l = self.free[il].lo if il is not None else getattr(self.base, lower)
        hi_l = self.free[il].hi if il is not None else getattr(self.base, lower)
        hi_u = self.free[iu].hi if iu is not None else getattr(self.base, upper)
        if iu is not None and not hi_u > hi_l + MIN_GAP_C:
            raise FreeParameterError(f"--free {upper}: its upper bound {hi_u:g} must exceed {lower}'s largest "
                                     f"value {hi_l:g} by more than {MIN_GAP_C:g} degC")
        if iu is None and not lo_l < hi_u - MIN_GAP_C:
            raise FreeParameterError(f"--free {lower}: its lower bound {lo_l:g} must be below {upper} = "
                                     f"{hi_u:g} (held) by more than {MIN_GAP_C:g} degC")

    def _limits(self, i: int, values: dict[str, float]) -> tuple[float, float]:
        """Bounds of free parameter i given the values decided so far (ordered pairs)."""
        f = self.free[i]
        lo, hi = f.lo, f.hi
        for lower, upper in ORDERED_PAIRS:
            if f.name == upper:
                lo = max(lo, values.get(lower, getattr(self.base, lower)) + MIN_GAP_C)
            elif f.name == lower and upper not in self._index:
                hi = min(hi, getattr(self.base, upper) - MIN_GAP_C)
        return lo, hi

    def _order(self) -> list[int]:
        """Each field after the lower members of its pairs, so that an upper member's range is known."""
        return sorted(range(self.n), key=lambda i: _rank(self.names[i]))

    def values(self, u) -> dict[str, float]:
        """Field values at the point u of the unit box."""
        u = np.clip(np.asarray(u, dtype=np.float64), 0.0, 1.0)
        out: dict[str, float] = {}
        for i in self._order():
            out[self.names[i]] = float(self.free[i].from_unit(float(u[i]), *self._limits(i, out)))
        return {n: out[n] for n in self.names}

    def to_unit(self, values: dict[str, float]) -> np.ndarray:
        """The point of the unit box holding ``values`` (clipped into the box)."""
        u = np.empty(self.n)
        decided: dict[str, float] = {}
        for i in self._order():
            v = float(values[self.names[i]])
            u[i] = self.free[i].to_unit(v, *self._limits(i, decided))
            decided[self.names[i]] = v
        return u

    def start(self) -> np.ndarray:
        return self.to_unit({f.name: getattr(self.base, f.fields[0]) for f in self.free})

    def fields(self, values: dict[str, float]) -> dict[str, float]:
        """Free values -> field values (tied fields each get their value)."""
        out = {}
        for f in self.free:
            out.update({name: values[f.name] for name in f.fields})
        return out

    def params(self, u) -> ParameterSet:
        """The base set with the values at u (validated)."""
        return self.base.replace(**self.fields(self.values(u)))

    def value_jacobian(self, u, step: float = 1e-6) -> np.ndarray:
        """d(values)/du at u (central differences of the map; no simulation)."""
        u = np.asarray(u, dtype=np.float64)
        D = np.empty((self.n, self.n))
        for j in range(self.n):
            a, b = u.copy(), u.copy()
            a[j], b[j] = max(u[j] - step, 0.0), min(u[j] + step, 1.0)
            va, vb = self.values(a), self.values(b)
            D[:, j] = [(vb[n] - va[n]) / (b[j] - a[j]) for n in self.names]
        return D

    def at_bounds(self, u, tol: float = 1e-3) -> list[str]:
        """Names of the parameters within ``tol`` (in the unit box) of a bound."""
        u = np.asarray(u)
        return [n for n, ui in zip(self.names, u) if ui <= tol or ui >= 1.0 - tol]
