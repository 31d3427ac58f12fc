"""The return-point-memory rule along an exact trajectory (docs/hysteresis.md, "The memory rule").

Written from the documented rules, not from ``smafinger.model``: a list of reversal points, no
capacity (the model merges loops beyond 64 open ones; these runs stay far below). The
trajectory stops at every event that changes the branch, so nothing is approximated within a
step: a reversal is taken where the driving tau turns (its extreme), and a loop is wiped out
where tau reaches its target. Between events tau moves one way, so a branch never holds.

Only c_A = c_M: tau_A and tau_M then move together and one tau drives both kinds of branch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import brentq

from .hysteresis import Affine, MemoryBranch, reached
from .material import Transformation, cooling_curve, heating_curve

#: a committed xi further than this outside the major loop is clamped onto it (and counted)
LOOP_TOL = 1e-12


@dataclass(frozen=True)
class Point:
    """A state's stress-shifted temperatures, its xi, and the major curves' values there."""

    tau_A: float
    tau_M: float
    xi: float
    g_A: float
    g_M: float
    reached_by: Affine | None = None  #: for a reversal point: the branch that led to it

    def tau(self, direction: int) -> float:
        return self.tau_A if direction > 0 else self.tau_M

    def g(self, direction: int) -> float:
        return self.g_A if direction > 0 else self.g_M


def at(T: float, sigma: float, m: Transformation, xi: float = math.nan) -> Point:
    return Point(T - sigma / m.c_A, T - sigma / m.c_M, xi, heating_curve(T, sigma, m)[0],
                 cooling_curve(T, sigma, m)[0])


class Memory:
    """One wire's kinetics under the memory rule: the current branch and the open reversal points."""

    def __init__(self, xi_init: float, m: Transformation):
        self.m = m
        self.direction = 0  #: +1 heating branch, -1 cooling branch, 0 not yet moved (holds xi_init)
        self.branch = Affine(xi_init, 0.0, 0.0)
        self.points: list[Point] = []  #: reversal points, alternating kinds, innermost last
        self.clamps = 0

    # ---- the branch a wire follows until the next event ------------------------------------
    def held(self) -> MemoryBranch:
        """The branch as the model holds it over a stretch (tau moves away from the anchor)."""
        d = self.direction
        behind = -math.inf if d >= 0 else math.inf  # never back from the extreme
        if len(self.points) >= 2:
            t = self.points[-2]
            return MemoryBranch(d, self.branch, behind, math.nan, t.tau(d), t.reached_by)
        return MemoryBranch(d, self.branch, behind, math.nan, -behind, self.branch)

    def target_tau(self) -> float:
        """The driving tau at which the current branch's inner loop closes (+-inf: none)."""
        return self.held().target

    # ---- events ----------------------------------------------------------------------------
    def move(self, direction: int, T: float, sigma: float) -> None:
        """Commit the state at (T, sigma) and follow ``direction`` (+1 tau rising, -1 falling, 0 still)."""
        here = at(T, sigma, self.m)
        if self.direction == 0:
            if direction == 0:
                return
            xi = self.branch.x0
            self.clamps += xi > here.g_A + LOOP_TOL or xi < here.g_M - LOOP_TOL
            xi = min(max(xi, here.g_M), here.g_A)
            self._no_history(here, xi, T, sigma)
        else:
            self._wipe_out(here)
            xi = self.branch.at(here.g(self.direction))
            if xi > here.g_A + LOOP_TOL or xi < here.g_M - LOOP_TOL:  # a major curve erases the history
                self.clamps += 1
                self._no_history(here, min(max(xi, here.g_M), here.g_A), T, sigma)
                xi = self.branch.x0
            xi = min(max(xi, here.g_M), here.g_A)
        if direction == -self.direction:
            self._reverse(here, xi, direction)

    def pass_target(self) -> None:
        """tau has reached the target: the inner loop is wiped out, the branch that led there resumes."""
        self.branch = self.points[-2].reached_by
        del self.points[-2:]

    # ---- the rules -------------------------------------------------------------------------
    def _aim(self, direction: int, xi: float, g: float) -> Affine:
        """The branch through (g, xi) aimed at the previous reversal point of the other kind, or at
        the end of the major curve (heating: xi = 0 at g_A = 0; cooling: xi = 1 at g_M = 1)."""
        if len(self.points) >= 2:
            x_t, g_t = self.points[-2].xi, self.points[-2].g(direction)
        else:
            x_t, g_t = (0.0, 0.0) if direction > 0 else (1.0, 1.0)
        slope = 0.0 if g == g_t else max((xi - x_t) / (g - g_t), 0.0)
        return Affine(xi, g, slope)

    def _wipe_out(self, here: Point) -> None:
        d = self.direction
        while len(self.points) >= 2 and reached(d, here.tau(d), self.points[-2].tau(d)):
            self.pass_target()

    def _reverse(self, here: Point, xi: float, direction: int) -> None:
        """A reversal at ``here``: push the point, then aim the new branch from it."""
        self.points.append(Point(here.tau_A, here.tau_M, xi, here.g_A, here.g_M, self.branch))
        while len(self.points) >= 2 and self._closed(self.points[-2], direction, here, xi):
            del self.points[-2:]
        self.direction = direction
        self.branch = self._aim(direction, xi, here.g(direction))

    @staticmethod
    def _closed(target: Point, direction: int, here: Point, xi: float) -> bool:
        """A target already reached here, or one a branch from here could not end at (same g, other xi)."""
        return (reached(direction, here.tau(direction), target.tau(direction))
                or (target.g(direction) == here.g(direction) and abs(target.xi - xi) > LOOP_TOL))

    def _no_history(self, here: Point, xi: float, T: float, sigma: float) -> None:
        """Start from (here, xi) as the simplest history that gives xi (docs: "no known history").

        On the major heating curve: that curve; on the major cooling curve: that curve; inside the
        loop: from full martensite up the major heating curve to a point R, then down R's
        first-order cooling curve (aimed at xi = 1, g_M = 1) to here.
        """
        self.points = []
        if xi >= here.g_A - LOOP_TOL:
            self.direction, self.branch = 1, self._aim(1, xi, here.g_A)
            return
        if xi <= here.g_M + LOOP_TOL:
            self.direction, self.branch = -1, self._aim(-1, xi, here.g_M)
            return
        m = self.m

        def through(T_R):  # the first-order cooling curve from R, at here's g_M, minus xi
            R = at(T_R, sigma, m)
            slope = 0.0 if R.g_M == 1.0 else max((R.g_A - 1.0) / (R.g_M - 1.0), 0.0)
            return R.g_A + slope * (here.g_M - R.g_M) - xi

        hi = max(T, m.A_F0 + sigma / m.c_A, m.M_S0 + sigma / m.c_M) + 1.0
        R = at(brentq(through, T, hi, xtol=1e-13, rtol=1e-15), sigma, m)
        self.points = [Point(R.tau_A, R.tau_M, R.g_A, R.g_A, R.g_M, Affine(R.g_A, R.g_A, 1.0 if R.g_A else 0.0))]
        self.direction, self.branch = -1, self._aim(-1, xi, here.g_M)
