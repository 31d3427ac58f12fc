"""Eqs. (9)-(10): which curve a wire's xi follows over a stretch of time, for each hysteresis rule.

Written from the paper, ``shared/MODEL-NOTES.md`` ("Minor loops") and ``docs/hysteresis.md``,
not from ``smafinger.model``. Two kinds of branch, each with ``fraction(T, sigma, m)``:

- :class:`Kinetics`: a branch of the legacy rules (``authors2020``, ``deadband``): the paper's
  scaled curves, heating xi = xi_M0 g_A (Eq. 9b), cooling xi = xi_A0 + (1 - xi_A0) g_M (Eq. 10b),
  or a hold; clipped to [0, 1]. :func:`next_phase` and :func:`enter` switch them.
- :class:`MemoryBranch`: a branch of the return-point-memory rule as the model holds it over a
  sub-step (docs/hysteresis.md, "The memory rule" and "Within a sub-step"): an affine image
  xi = x0 + b (g - g0) of a major curve, holding behind its extreme, continuing on its parent
  branch past its target, kept inside the major loop g_M(tau_M) <= xi <= g_A(tau_A).
  :mod:`.memory` moves it along an exact trajectory.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

from .material import Transformation, cooling_curve, heating_curve


class Phase(Enum):
    """Which kinetics curve a wire follows under a legacy rule (MODEL-NOTES: the sign of dT/dt)."""

    HOLD = "hold"  #: dT/dt = 0: xi stays where it is
    HEATING = "heating"  #: Eq. (9), martensite -> austenite, start value xi_M0
    COOLING = "cooling"  #: Eq. (10), austenite -> martensite, start value xi_A0


@dataclass(frozen=True)
class Fraction:
    """xi with its partial derivatives, and the round-off scale of those partials.

    Inside a band a partial is a sine of an argument with round-off of its own: near the band's
    ends, where the sine is small, its round-off is that of its amplitude (``amp_T``, ``amp_s``).
    """

    xi: float
    xi_T: float
    xi_s: float
    amp_T: float = 0.0
    amp_s: float = 0.0


def _curve(direction: int, T: float, sigma: float, m: Transformation):
    """(g, dg/dT, dg/dsigma, amplitude of dg/dT) of the heating (+1) or cooling (-1) major curve."""
    if direction > 0:
        g, gT, gs = heating_curve(T, sigma, m)
        width = m.A_F0 - m.A_S0
    else:
        g, gT, gs = cooling_curve(T, sigma, m)
        width = m.M_S0 - m.M_F0
    inside = not (gT == 0.0 and g in (0.0, 1.0))
    return g, gT, gs, (0.5 * math.pi / width if inside else 0.0)


def _scaled(factor: float, xi: float, gT: float, gs: float, amp: float, c: float) -> Fraction:
    a = abs(factor) * amp
    return Fraction(xi, factor * gT, factor * gs, a, a / c)


# --------------------------------------------------------------------------------------------
# the legacy rules: the paper's scaled curves, start values re-solved at a change of branch
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Kinetics:
    """A legacy rule's branch: its curve and that curve's start value (or the held xi)."""

    phase: Phase
    start: float  #: xi_M0 (heating) or xi_A0 (cooling)
    held: float  #: xi while holding

    def fraction(self, T: float, sigma: float, m: Transformation) -> Fraction:
        """xi on this branch; kept in [0, 1] (flat where clipped)."""
        if self.phase is Phase.HOLD:
            return Fraction(self.held, 0.0, 0.0)
        if self.phase is Phase.HEATING:
            g, gT, gs, amp = _curve(1, T, sigma, m)
            xi, factor, c = self.start * g, self.start, m.c_A
        else:
            g, gT, gs, amp = _curve(-1, T, sigma, m)
            xi, factor, c = self.start + (1.0 - self.start) * g, 1.0 - self.start, m.c_M
        if xi < 0.0:
            return Fraction(0.0, 0.0, 0.0)
        if xi > 1.0:
            return Fraction(1.0, 0.0, 0.0)
        return _scaled(factor, xi, gT, gs, amp, c)


def start_through(phase: Phase, xi: float, T: float, sigma: float, m: Transformation) -> float:
    """The start value that puts the curve of ``phase`` through xi at (T, sigma) (minor loops).

    MODEL-NOTES: the authors' model re-solves the start value at every reversal so that xi is
    continuous. Where the curve no longer depends on its start (above A_F on heating, below
    M_F on cooling) the major loop's value is taken (1, respectively 0).
    """
    if phase is Phase.HEATING:
        g = heating_curve(T, sigma, m)[0]
        return xi / g if g > 1e-12 else 1.0
    if phase is Phase.COOLING:
        g = cooling_curve(T, sigma, m)[0]
        return (xi - g) / (1.0 - g) if 1.0 - g > 1e-12 else 0.0
    return xi


def next_phase(phase: Phase, sign: int, T: float, turn: float, rev: float) -> tuple[Phase, float]:
    """(branch, turn) of a legacy rule at a state where T moves with ``sign`` (+1, -1, 0).

    ``rev`` = 0 (authors2020): the sign of dT/dt. ``rev`` > 0 (deadband): the branch changes only
    once T has moved back by ``rev`` from its extreme ``turn`` since the last change.
    """
    if rev <= 0.0:
        return {1: Phase.HEATING, -1: Phase.COOLING, 0: Phase.HOLD}[sign], T
    if phase is Phase.HEATING:
        return (Phase.COOLING, T) if T < turn - rev else (phase, max(turn, T))
    if phase is Phase.COOLING:
        return (Phase.HEATING, T) if T > turn + rev else (phase, min(turn, T))
    if T > turn + rev:
        return Phase.HEATING, T
    if T < turn - rev:
        return Phase.COOLING, T
    return phase, turn


def enter(phase: Phase, k: Kinetics, xi: float, T: float, sigma: float, m: Transformation) -> Kinetics:
    """The legacy branch on entering ``phase`` with xi at (T, sigma): continuous xi (MODEL-NOTES)."""
    if phase is Phase.HOLD:
        return Kinetics(phase, k.start, xi)
    return Kinetics(phase, start_through(phase, xi, T, sigma, m), k.held)


# --------------------------------------------------------------------------------------------
# the memory rule
# --------------------------------------------------------------------------------------------
def own_tau(direction: int, T: float, sigma: float, m: Transformation) -> float:
    """The stress-shifted temperature that drives a branch: tau_A = T - sigma/c_A heating, tau_M cooling."""
    return T - sigma / (m.c_A if direction > 0 else m.c_M)


def reached(direction: int, tau: float, mark: float) -> bool:
    """tau has reached ``mark`` moving in ``direction`` (heating: rising, cooling: falling)."""
    return tau >= mark if direction > 0 else tau <= mark


@dataclass(frozen=True)
class Affine:
    """xi = x0 + slope (g - g0): an affine image of a major curve, written about its anchor."""

    x0: float
    g0: float
    slope: float

    def at(self, g: float) -> float:
        return self.x0 + self.slope * (g - self.g0)


@dataclass(frozen=True)
class MemoryBranch:
    """The memory rule's branch over a sub-step (docs/hysteresis.md).

    ``direction`` +1 heating (driven by tau_A, curve g_A), -1 cooling (tau_M, g_M), 0 the
    virgin hold at ``branch.x0``. ``extreme`` is the furthest the branch's own tau had gone
    and ``g_extreme`` its major-curve value there: while tau is back from it, xi holds at the
    branch's value there. ``target`` (own tau; +-inf: none) is where the inner loop closes:
    from it on, xi follows ``parent``, the branch that led to the target.
    """

    direction: int
    branch: Affine
    extreme: float
    g_extreme: float
    target: float
    parent: Affine

    def fraction(self, T: float, sigma: float, m: Transformation) -> Fraction:
        d = self.direction
        if d == 0:
            return Fraction(self.branch.x0, 0.0, 0.0)
        gA, gAT, gAs, ampA = _curve(1, T, sigma, m)
        gM, gMT, gMs, ampM = _curve(-1, T, sigma, m)
        g, gT, gs, amp = (gA, gAT, gAs, ampA) if d > 0 else (gM, gMT, gMs, ampM)
        c = m.c_A if d > 0 else m.c_M
        tau = own_tau(d, T, sigma, m)
        if not reached(d, tau, self.extreme):  # back from the extreme: xi holds
            out = Fraction(self.branch.at(self.g_extreme), 0.0, 0.0)
        elif reached(d, tau, self.target):
            out = _scaled(self.parent.slope, self.parent.at(g), gT, gs, amp, c)
        else:
            out = _scaled(self.branch.slope, self.branch.at(g), gT, gs, amp, c)
        if out.xi < gM:  # below the major cooling curve: on it
            out = Fraction(gM, gMT, gMs, ampM, ampM / m.c_M)
        if out.xi > gA:  # above the major heating curve: on it
            out = Fraction(gA, gAT, gAs, ampA, ampA / m.c_A)
        return out
