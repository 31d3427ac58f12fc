"""Fixed-step explicit integrators. Each declares its order of accuracy.

They advance a :class:`~smafinger.model.records.State` (a NamedTuple: each field of the
mechanism and of every wire) over one sub-step with the inputs held. ``k1`` = f(y) is given:
the engine evaluates it at every sub-step start for its discrete decisions anyway.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

from numba import njit

from ..model.records import State, WireState
from .rhs import derivative, geometry_at
from .tuples import set_item


class Method(IntEnum):
    EULER = 0
    RK4 = 1


@dataclass(frozen=True)
class Integrator:
    name: str
    order: int
    code: Method
    stages: int


EULER = Integrator("euler", order=1, code=Method.EULER, stages=1)
RK4 = Integrator("rk4", order=4, code=Method.RK4, stages=4)
INTEGRATORS = {i.name: i for i in (EULER, RK4)}


def get(name: str) -> Integrator:
    try:
        return INTEGRATORS[name]
    except KeyError:
        raise ValueError(f"method = {name!r} is not one of {', '.join(INTEGRATORS)}") from None


@njit(cache=True)
def _wire_axpy(a, c, b):
    return WireState(a.T_C + c * b.T_C, a.sigma_Pa + c * b.sigma_Pa, a.electrical_J + c * b.electrical_J,
                     a.heat_J + c * b.heat_J, a.T_case_C + c * b.T_case_C)


@njit(cache=True, inline="always")
def axpy(y, c, k):
    """y + c k, field by field."""
    ws = y.wires
    for i in range(len(ws)):
        ws = set_item(ws, i, _wire_axpy(y.wires[i], c, k.wires[i]))
    return State(y.q + c * k.q, y.v + c * k.v, y.error_integral + c * k.error_integral, ws)


@njit(cache=True, inline="always")
def step(method, model, y, h, inputs, k1, geom):
    """y advanced by h: explicit Euler (order 1) or classical RK4 (order 4). Returns (y, evaluations).

    RK4 as a loop over its three later stages (one right-hand-side call site, so that it is
    compiled once): the weighted sum accumulates k1 + 2 k2 + 2 k3 + k4 in that order.
    """
    if method == Method.EULER:
        return axpy(y, h, k1), 0
    half = 0.5 * h
    acc = k1
    k = k1
    q_prev = y.q
    g = geom
    for stage in range(3):
        yk = axpy(y, h if stage == 2 else half, k)
        g = geometry_at(yk.q, q_prev, g, model)
        q_prev = yk.q
        k, _ = derivative(yk, inputs, model, g)
        acc = axpy(acc, 1.0 if stage == 2 else 2.0, k)
    return axpy(y, h / 6.0, acc), 3
