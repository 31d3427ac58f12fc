"""Fixed-step explicit integrators. Each declares its order of accuracy."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Integrator:
    name: str
    order: int
    code: int
    stages: int


EULER = Integrator("euler", order=1, code=0, stages=1)
RK4 = Integrator("rk4", order=4, code=1, stages=4)
INTEGRATORS = {i.name: i for i in (EULER, RK4)}


def get(name: str) -> Integrator:
    try:
        return INTEGRATORS[name]
    except KeyError:
        raise ValueError(f"method = {name!r} is not one of {', '.join(INTEGRATORS)}") from None
