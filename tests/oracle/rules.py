"""Each wire's hysteresis rule along an exact trajectory: what drives it, its events, its updates.

A rule object holds one wire's kinetics between the trajectory's events and offers:

- ``held()``: the branch (:class:`~.hysteresis.Kinetics` or :class:`~.hysteresis.MemoryBranch`)
  for the right-hand side until the next event;
- ``rate(dT, dsigma)``: the rate of the quantity that drives it (T for the legacy rules, the
  stress-shifted tau = T - sigma/c for the memory rule); ``motion`` is that rate's sign over
  the current stretch (0: still), and the trajectory stops where it turns;
- ``marks()``: levels of the driving quantity at which the rule acts (``name``, level,
  crossing direction), with ``level(T, sigma)`` and ``on_mark(name, T, sigma, xi)``;
- ``update(sign, T, sigma, xi)``: commit the state at a discrete moment, moving with ``sign``.
"""

from __future__ import annotations

import math

from .hysteresis import Kinetics, Phase, enter, next_phase
from .material import Transformation
from .memory import Memory


class Legacy:
    """``authors2020`` (``rev`` = 0): the branch follows the sign of dT/dt; ``deadband`` (``rev`` > 0):
    it changes once T has moved back by ``rev`` from its extreme (MODEL-NOTES, docs/hysteresis.md)."""

    def __init__(self, xi_init: float, T_init: float, rev: float, m: Transformation):
        self.branch = Kinetics(Phase.HOLD, xi_init, xi_init)
        self.turn, self.rev, self.m = T_init, rev, m
        self.motion = 0

    def held(self) -> Kinetics:
        return self.branch

    def rate(self, dT: float, dsigma: float) -> float:
        return dT

    def level(self, T: float, sigma: float) -> float:
        return T

    def update(self, sign: int, T: float, sigma: float, xi: float) -> None:
        self.motion = sign
        phase, self.turn = next_phase(self.branch.phase, sign, T, self.turn, self.rev)
        if phase is not self.branch.phase:
            self.branch = enter(phase, self.branch, xi, T, sigma, self.m)

    def marks(self) -> list[tuple[str, float, int]]:
        if self.rev <= 0.0:
            return []
        out = []
        if self.branch.phase is not Phase.COOLING:  # heating or holding: a fall by rev from the turn
            out.append(("cool", self.turn - self.rev, -1))
        if self.branch.phase is not Phase.HEATING:
            out.append(("heat", self.turn + self.rev, 1))
        return out

    def on_mark(self, name: str, T: float, sigma: float, xi: float) -> None:
        phase = Phase.HEATING if name == "heat" else Phase.COOLING
        self.branch = enter(phase, self.branch, xi, T, sigma, self.m)
        self.turn = T


class MemoryRule:
    """``memory``: return-point memory, driven by tau = T - sigma/c (c_A = c_M only)."""

    def __init__(self, xi_init: float, m: Transformation):
        if m.c_A != m.c_M:
            raise NotImplementedError("the oracle's memory rule along a trajectory needs c_A = c_M (one driving tau)")
        self.memory = Memory(xi_init, m)
        self.c = m.c_A
        self.motion = 0

    def held(self):
        return self.memory.held()

    def rate(self, dT: float, dsigma: float) -> float:
        return dT - dsigma / self.c

    def level(self, T: float, sigma: float) -> float:
        return T - sigma / self.c

    def update(self, sign: int, T: float, sigma: float, xi: float) -> None:
        self.motion = sign
        self.memory.move(sign, T, sigma)

    def marks(self) -> list[tuple[str, float, int]]:
        target = self.memory.target_tau()
        return [("target", target, self.memory.direction)] if math.isfinite(target) else []

    def on_mark(self, name: str, T: float, sigma: float, xi: float) -> None:
        self.memory.pass_target()


def make_rule(rule: str, xi_init: float, T_init: float, rev: float, m: Transformation):
    """The rule object of a wire for the model's ``hysteresis`` option."""
    if rule == "memory":
        return MemoryRule(xi_init, m)
    return Legacy(xi_init, T_init, rev, m)
