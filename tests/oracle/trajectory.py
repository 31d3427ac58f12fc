"""Open-loop runs of the oracle with ``scipy.integrate.solve_ivp``; the discrete parts as events.

Between the program's changes of drive (and PWM edges) the right-hand side is smooth but for
three hybrid parts, each handled as a terminal event that stops the integration, updates the
discrete state and restarts it:

- stick/slip, Eq. (2): a held mechanism breaks away when |M_E| rises through M_SF; with the
  ``restick`` option a moving one sticks again when |q'| falls through the stick velocity while
  |M_E| <= M_SF (if |M_E| > M_SF it creeps, and sticks when |M_E| falls through M_SF);
- end stops (the slider): reaching one stops the slider there; it stays while its load pushes
  into the stop (or, with ``restick``, while |load| <= the static friction) and leaves when
  pulled away by more than the static friction;
- kinetics branches (MODEL-NOTES): at each change of drive a wire's branch follows the sign of
  dT/dt (with a constant drive T is monotone, so the sign holds until the next change); with
  ``minor_loop_reversal_C`` > 0 the branch changes only once T has moved back by that much from
  its extreme since the last change, an event on T. At a change the new curve's start value is
  re-solved through the current xi (continuous xi).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from .material import Kinetics, Phase, start_through
from .model import Held, OracleModel, Vars, WireHeld, WireVars
from .program import Stretch
from .rhs import derivative


class Mode(Enum):
    SLIDING = "sliding"
    CREEPING = "creeping"  #: slower than the stick velocity, but |M_E| > M_SF
    STUCK = "stuck"


@dataclass
class Hybrid:
    """The discrete state: stick/slip mode, the stop held against, each wire's kinetics."""

    mode: Mode
    stop: int  #: +1 held at q_max, -1 at q_min, 0 elsewhere
    kinetics: list[Kinetics]
    turns: list[float]  #: extreme temperature since each wire's last change of branch


@dataclass
class Trajectory:
    """An oracle run sampled on a grid: coordinate, rate, error integral and per-wire signals."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    error_integral: np.ndarray
    wires: dict[str, dict[str, np.ndarray]]  #: name -> T, sigma, xi, energy
    info: dict = field(default_factory=dict)  #: wall_s, nfev, calls, events


def _vars(y, n: int) -> Vars:
    return Vars(y[0], y[1], y[2], tuple(WireVars(y[3 + i], y[3 + n + i], y[3 + 2 * n + i]) for i in range(n)))


def _vector(m: OracleModel, d) -> list[float]:
    names = [w.name for w in m.wires]
    r = d.rates
    return ([r["q"], r["v"], r["error_integral"]] + [r[n + ".T"] for n in names]
            + [r[n + ".sigma"] for n in names] + [r[n + ".energy"] for n in names])


class _Segment:
    """The right-hand side and the events of one stretch of constant drive and discrete state."""

    def __init__(self, m: OracleModel, hy: Hybrid, held: Held, rev: float):
        self.m, self.hy, self.held, self.rev = m, hy, held, rev
        self.n = len(m.wires)
        self._key, self._d = None, None
        self.nfev = 0

    def at(self, t, y):
        key = (t, tuple(y))
        if key != self._key:
            self._key, self._d = key, derivative(self.m, _vars(y, self.n), self.held)
        return self._d

    def rhs(self, t, y):
        self.nfev += 1
        return _vector(self.m, self.at(t, y))

    def events(self) -> list[tuple[str, object]]:
        """(name, event function) pairs for solve_ivp, from the discrete state."""
        mc, hy, ev = self.m.mechanism, self.hy, []
        load = lambda t, y: self.at(t, y).outputs["load"]  # noqa: E731
        if hy.mode is Mode.STUCK:
            if hy.stop:
                ev.append(("release", _event(lambda t, y: -hy.stop * load(t, y) - mc.static, 1)))
            else:
                ev.append(("release", _event(lambda t, y: abs(load(t, y)) - mc.static, 1)))
        else:
            # with no static friction Eq. (2) holds only where the load is exactly 0: no sticking
            if self.m.restick and mc.static > 0.0 and hy.mode is Mode.SLIDING:
                ev.append(("slow", _event(lambda t, y: abs(y[1]) - mc.stick_velocity, -1)))
            if hy.mode is Mode.CREEPING:
                ev.append(("weak", _event(lambda t, y: abs(load(t, y)) - mc.static, -1)))
                ev.append(("fast", _event(lambda t, y: abs(y[1]) - mc.stick_velocity, 1)))
            if math.isfinite(mc.q_max):
                ev.append(("stop+", _event(lambda t, y: y[0] - mc.q_max, 1)))
            if math.isfinite(mc.q_min):
                ev.append(("stop-", _event(lambda t, y: y[0] - mc.q_min, -1)))
        if self.rev > 0.0:
            for i, k in enumerate(hy.kinetics):
                j = 3 + i
                if k.phase is not Phase.COOLING:  # heating or holding: a fall by rev from the turn
                    ev.append((f"cool{i}", _event(lambda t, y, j=j, c=hy.turns[i] - self.rev: y[j] - c, -1)))
                if k.phase is not Phase.HEATING:
                    ev.append((f"heat{i}", _event(lambda t, y, j=j, c=hy.turns[i] + self.rev: y[j] - c, 1)))
        return ev


def _event(f, direction: int):
    f.terminal, f.direction = True, direction
    return f


# --------------------------------------------------------------------------------------------
# discrete updates
# --------------------------------------------------------------------------------------------
def next_phase(phase: Phase, dT: float, T: float, turn: float, rev: float) -> tuple[Phase, float]:
    """(branch, turn) at a change of drive: the sign of dT/dt, or the reversal dead band ``rev``."""
    if rev <= 0.0:
        return (Phase.HEATING if dT > 0.0 else Phase.COOLING if dT < 0.0 else Phase.HOLD), T
    if phase is Phase.HEATING:
        if T < turn - rev:
            return Phase.COOLING, T
        return phase, max(turn, T)
    if phase is Phase.COOLING:
        if T > turn + rev:
            return Phase.HEATING, T
        return phase, min(turn, T)
    if T > turn + rev:
        return Phase.HEATING, T
    if T < turn - rev:
        return Phase.COOLING, T
    return phase, turn


def enter(phase: Phase, k: Kinetics, xi: float, T: float, sigma: float, m) -> Kinetics:
    """The kinetics on entering ``phase`` with xi at (T, sigma): continuous xi (MODEL-NOTES)."""
    if phase is Phase.HOLD:
        return Kinetics(phase, k.start, xi)
    return Kinetics(phase, start_through(phase, xi, T, sigma, m), k.held)


def _switch_branches(seg: _Segment, y, rev: float) -> None:
    """At a change of drive: each wire's branch for the stretch (the drive is in ``seg.held``)."""
    d = seg.at(None, y)
    hy = seg.hy
    for i, w in enumerate(seg.m.wires):
        T = y[3 + i]
        phase, hy.turns[i] = next_phase(hy.kinetics[i].phase, d.rates[w.name + ".T"], T, hy.turns[i], rev)
        if phase is not hy.kinetics[i].phase:
            hy.kinetics[i] = enter(phase, hy.kinetics[i], d.outputs[w.name + ".xi"], T,
                                   d.outputs[w.name + ".sigma"], w.transformation)


def _on_event(name: str, seg: _Segment, y) -> None:
    """Apply the event ``name`` to the discrete state ``seg.hy`` and the state vector y."""
    hy, mc, d = seg.hy, seg.m.mechanism, seg.at(None, y)
    load = d.outputs["load"]
    if name == "release":
        hy.mode, hy.stop = Mode.SLIDING, 0
    elif name in ("slow", "weak"):
        hy.mode = Mode.STUCK if abs(load) <= mc.static or name == "weak" else Mode.CREEPING
    elif name == "fast":
        hy.mode = Mode.SLIDING
    elif name.startswith("stop"):
        side = 1 if name == "stop+" else -1
        y[0] = mc.q_max if side > 0 else mc.q_min
        y[1] = 0.0
        if side * load > 0.0 or (seg.m.restick and abs(load) <= mc.static):
            hy.mode, hy.stop = Mode.STUCK, side
        else:
            hy.mode = Mode.SLIDING
    else:  # a kinetics dead band: heat<i> or cool<i>
        i = int(name[4:])
        w = seg.m.wires[i]
        phase = Phase.HEATING if name.startswith("heat") else Phase.COOLING
        hy.kinetics[i] = enter(phase, hy.kinetics[i], d.outputs[w.name + ".xi"], y[3 + i],
                               d.outputs[w.name + ".sigma"], w.transformation)
        hy.turns[i] = y[3 + i]
    if hy.mode is Mode.STUCK:
        y[1] = 0.0


def _held(m: OracleModel, hy: Hybrid, st: Stretch, current: bool) -> Held:
    viscous = m.mechanism.viscous_heating if any(st.on) else m.mechanism.viscous_cooling
    return Held(hy.mode is Mode.STUCK, viscous, m.initial_target, 1.0, current,
                tuple(WireHeld(dr, on, k) for dr, on, k in zip(st.drives, st.on, hy.kinetics)))
