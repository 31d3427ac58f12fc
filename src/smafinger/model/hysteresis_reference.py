"""Pure-Python reference of the return-point-memory rule (test oracle, no numba).

Written from the rules (``docs/hysteresis.md``) with objects instead of a fixed array: a list
of reversal points, each holding the branch that reached it, and no capacity. Over a sampled
history (T_k, sigma_k), the input moves monotonically between samples; every loop whose
target is reached within an interval is wiped out at the interval's end, so there is no
within-step approximation. It records what the property tests need to see: the gap between
the two branches at every wiped-out target (continuity) and the number of targets reached
in each interval (``passes``), every flat branch built between two
points of equal g with the difference of their xi (``flat_gaps``; ``unreachable`` when that
difference would make the branch skip its target), and every clamp to the major loop.
"""

from dataclasses import dataclass, field

import numpy as np

from .kinetics import g_cooling, g_heating

LOOP_TOL = 1e-12


@dataclass(frozen=True)
class Branch:
    """xi = x0 + slope (g - g0), g = g_A (direction +1) or g_M (-1)."""

    direction: int
    x0: float
    g0: float
    slope: float

    def at(self, g):
        return self.x0 + self.slope * (g - self.g0)


@dataclass(frozen=True)
class Point:
    """A state (tau_A, tau_M, xi) with its major-curve values, and the branch that reached it."""

    tau_A: float
    tau_M: float
    xi: float
    g_A: float
    g_M: float
    reached_by: Branch | None = None

    def tau(self, direction):
        return self.tau_A if direction > 0 else self.tau_M

    def g(self, direction):
        return self.g_A if direction > 0 else self.g_M


@dataclass
class HysteresisOperator:
    """Return-point-memory operator over a sampled history; ``run(T, sigma)`` gives xi."""

    material: object
    xi_init: float = 1.0
    points: list = field(default_factory=list)
    branch: Branch | None = None
    extreme: Point | None = None  # where the branch's own tau went furthest (xi holds behind)
    pop_gaps: list = field(default_factory=list)
    passes: list = field(default_factory=list)
    unreachable: list = field(default_factory=list)
    flat_gaps: list = field(default_factory=list)
    clamps: int = 0

    # ---- the state at (T, sigma) -----------------------------------------------------------
    def _point(self, T, sigma, xi, reached_by=None):
        m = self.material
        gA = g_heating.py_func(T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)[0]
        gM = g_cooling.py_func(T, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)[0]
        return Point(T - sigma / m.c_A_Pa_per_C, T - sigma / m.c_M_Pa_per_C, xi, gA, gM,
                     reached_by)

    def _toward(self, direction, anchor_xi, anchor_g):
        """The branch through the anchor aimed at the point under the top, or at the end of
        the major curve."""
        if len(self.points) >= 2:
            x_t, g_t = self.points[-2].xi, self.points[-2].g(direction)
        else:
            x_t, g_t = (0.0, 0.0) if direction > 0 else (1.0, 1.0)
        return Branch(direction, anchor_xi, anchor_g, self._slope(anchor_xi, anchor_g, x_t, g_t))

    def _slope(self, x_r, g_r, x_t, g_t):
        if g_r == g_t:
            self.flat_gaps.append(abs(x_r - x_t))
            return 0.0
        return max((x_r - x_t) / (g_r - g_t), 0.0)

    def _unreachable(self, target, direction, xi, g):
        """Same g, other xi: a branch from here could not end there (logged: the rules
        guarantee it never happens without a merge, and the reference has no merges)."""
        if target.g(direction) == g and abs(target.xi - xi) > LOOP_TOL:
            self.unreachable.append(abs(target.xi - xi))
            return True
        return False

    @staticmethod
    def _reached(direction, tau, target_tau):
        return tau >= target_tau if direction > 0 else tau <= target_tau

    @staticmethod
    def _outside(xi, here):
        return xi > here.g_A + LOOP_TOL or xi < here.g_M - LOOP_TOL

    @staticmethod
    def _into_loop(xi, here):
        return min(max(xi, here.g_M), here.g_A)

    # ---- a wire with no known history ------------------------------------------------------
    def _major_heating_to(self, xi, T, sigma, g_M):
        """T_R of the point R on the major heating curve whose first-order cooling curve
        passes through (g_M, xi): bisection."""
        m = self.material
        lo = T
        hi = max(T, m.A_F0_C + sigma / m.c_A_Pa_per_C, m.M_S0_C + sigma / m.c_M_Pa_per_C) + 1.0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if not lo < mid < hi:
                break
            R = self._point(mid, sigma, 0.0)
            through = R.g_A + max((R.g_A - 1.0) / (R.g_M - 1.0), 0.0) * (g_M - R.g_M) \
                if R.g_M != 1.0 else R.g_A
            if through > xi:
                lo = mid
            else:
                hi = mid
        return lo

    def _forget(self, here, xi, T, sigma):
        """Start from (here, xi) with no history: on the major curve it lies on, or cooling
        on the first-order curve from the point R of the major heating curve through it."""
        self.points = []
        if xi >= here.g_A - LOOP_TOL:
            self.branch = self._toward(1, xi, here.g_A)
        elif xi <= here.g_M + LOOP_TOL:
            self.branch = self._toward(-1, xi, here.g_M)
        else:
            R = self._point(self._major_heating_to(xi, T, sigma, here.g_M), sigma, 0.0)
            major = Branch(1, R.g_A, R.g_A, self._slope(R.g_A, R.g_A, 0.0, 0.0))
            self.points = [Point(R.tau_A, R.tau_M, R.g_A, R.g_A, R.g_M, major)]
            self.branch = self._toward(-1, xi, here.g_M)

    # ---- one sample ------------------------------------------------------------------------
    def _wipe_out(self, here):
        b = self.branch
        while len(self.points) >= 2 and self._reached(b.direction, here.tau(b.direction),
                                                      self.points[-2].tau(b.direction)):
            target = self.points[-2]
            g_t = target.g(b.direction)
            self.pop_gaps.append(abs(b.at(g_t) - target.reached_by.at(g_t)))
            b = target.reached_by
            del self.points[-2:]
        self.branch = b

    def step(self, T, sigma, direction):
        """Commit the events at (T, sigma), then take ``direction`` (+1, -1, 0) for the next
        interval. Returns xi at (T, sigma)."""
        here = self._point(T, sigma, 0.0)
        if self.branch is None:
            if direction == 0:
                return self.xi_init
            self.clamps += self._outside(self.xi_init, here)
            xi = self._into_loop(self.xi_init, here)
            self._forget(here, xi, T, sigma)
            self.extreme = here
        else:
            self._wipe_out(here)
            d = self.branch.direction
            if self._reached(d, here.tau(d), self.extreme.tau(d)):
                self.extreme = here
            raw = self.branch.at(self.extreme.g(d))
            xi = self._into_loop(raw, here)
            if self._outside(raw, here):
                self.clamps += 1
                self._forget(here, xi, T, sigma)
                self.extreme = here
            if direction == 0:
                direction = self.branch.direction
        d = self.branch.direction
        if direction == -d:
            # the reversal point: the branch's extreme in its own tau, here in the other one
            e = self.extreme
            if d > 0:
                point = Point(e.tau_A, here.tau_M, xi, e.g_A, here.g_M, self.branch)
            else:
                point = Point(here.tau_A, e.tau_M, xi, here.g_A, e.g_M, self.branch)
            self.points.append(point)
            while len(self.points) >= 2 and (
                    self._reached(direction, here.tau(direction), self.points[-2].tau(direction))
                    or self._unreachable(self.points[-2], direction, xi, here.g(direction))):
                del self.points[-2:]
            self.branch = self._toward(direction, xi, here.g(direction))
            self.extreme = here
        return xi

    def direction(self, dT, dsigma):
        """+1 while tau_A rises, -1 while tau_M falls; both: keep the current one."""
        m = self.material
        dA = dT - dsigma / m.c_A_Pa_per_C
        dM = dT - dsigma / m.c_M_Pa_per_C
        if dA > 0.0 and dM < 0.0:
            if self.branch is not None:
                return self.branch.direction
            return 1 if dA + dM >= 0.0 else -1
        return 1 if dA > 0.0 else (-1 if dM < 0.0 else 0)

    def run(self, T, sigma):
        """xi at every sample of the history (T degC, sigma Pa)."""
        T = [float(v) for v in T]
        sigma = [float(v) for v in sigma]
        out = np.empty(len(T))
        direction = 0
        for k in range(len(T)):
            if k + 1 < len(T):
                direction = self.direction(T[k + 1] - T[k], sigma[k + 1] - sigma[k])
            before = len(self.pop_gaps)
            out[k] = self.step(T[k], sigma[k], direction)
            self.passes.append(len(self.pop_gaps) - before)
        return out
