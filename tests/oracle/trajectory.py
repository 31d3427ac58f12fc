"""Open-loop runs of the oracle with ``scipy.integrate.solve_ivp``; the discrete parts as events.

Between the program's changes of drive (and PWM edges) the right-hand side is smooth but for
hybrid parts, each handled as a terminal event that stops the integration, updates the discrete
state and restarts it:

- stick/slip, Eq. (2): a held mechanism breaks away when |M_E| rises through M_SF; with the
  ``restick`` option a moving one sticks again when |q'| falls through the stick velocity while
  |M_E| <= M_SF (if |M_E| > M_SF it creeps, and sticks when |M_E| falls through M_SF);
- end stops (the slider): reaching one stops the slider there; it stays while its load pushes
  into the stop (or, with ``restick``, while |load| <= the static friction) and leaves when
  pulled away by more than the static friction;
- kinetics (:mod:`.rules`): each wire's driving quantity (T, or tau = T - sigma/c for the memory
  rule) turning back (a reversal), and the levels at which its rule acts (a memory loop's
  target; the dead band's thresholds).

At every event, and at every change of drive, each wire's rule commits the state and takes the
sign of its driving rate, 0 (still) within ``RATE_TOL`` of 0; a still wire's start is an event.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from .model import Held, OracleModel, Vars, WireHeld, WireVars
from .program import Stretch
from .rhs import derivative

#: the state vector: the mechanism's components, then each per-wire component for every wire
MECHANISM_STATE = ("q", "v", "error_integral")
WIRE_STATE = ("T", "sigma", "electrical", "heat", "T_case")
#: a driving rate (degC/s) within this of 0 is round-off: the wire is still (a wire moving at it
#: moves its tau by 1e-8 degC in 10 s); a turn is taken once the rate is this far the other way
RATE_TOL = 1e-9


class Mode(Enum):
    SLIDING = "sliding"
    CREEPING = "creeping"  #: slower than the stick velocity, but |M_E| > M_SF
    STUCK = "stuck"


@dataclass
class Hybrid:
    """The discrete state: stick/slip mode, the stop held against, each wire's rule (:mod:`.rules`)."""

    mode: Mode
    stop: int  #: +1 held at q_max, -1 at q_min, 0 elsewhere
    rules: list


@dataclass
class Trajectory:
    """An oracle run sampled on a grid: coordinate, rate, error integral and per-wire signals."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    error_integral: np.ndarray
    wires: dict[str, dict[str, np.ndarray]]  #: name -> T, sigma, xi, electrical, heat, T_case
    info: dict = field(default_factory=dict)  #: wall_s, nfev, calls, events


def index(key: str, i: int, n: int) -> int:
    """Position of wire i's component ``key`` in the state vector of n wires."""
    return len(MECHANISM_STATE) + WIRE_STATE.index(key) * n + i


def _vars(y, n: int) -> Vars:
    wires = tuple(WireVars(**{k: y[index(k, i, n)] for k in WIRE_STATE}) for i in range(n))
    return Vars(y[0], y[1], y[2], wires)


def _vector(m: OracleModel, d) -> list[float]:
    r = d.rates
    return [r[k] for k in MECHANISM_STATE] + [r[f"{w.name}.{k}"] for k in WIRE_STATE for w in m.wires]


class _Segment:
    """The right-hand side and the events of one stretch of constant drive and discrete state."""

    def __init__(self, m: OracleModel, hy: Hybrid, held: Held):
        self.m, self.hy, self.held = m, hy, held
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

    def driving_rate(self, i: int, t, y) -> float:
        return self.hy.rules[i].rate(*self.at(t, y).drivers[self.m.wires[i].name])

    def level(self, i: int, t, y) -> float:
        w = self.m.wires[i]
        return self.hy.rules[i].level(y[index("T", i, self.n)], self.at(t, y).outputs[w.name + ".sigma"])

    def events(self) -> list[tuple[str, object]]:
        """(name, event function) pairs for solve_ivp, from the discrete state."""
        return self._mechanical_events() + self._kinetics_events()

    def _mechanical_events(self):
        mc, hy, ev = self.m.mechanism, self.hy, []
        load = lambda t, y: self.at(t, y).outputs["load"]  # noqa: E731
        if hy.mode is Mode.STUCK:
            if hy.stop:
                ev.append(("release", _event(lambda t, y: -hy.stop * load(t, y) - mc.static, 1)))
            else:
                ev.append(("release", _event(lambda t, y: abs(load(t, y)) - mc.static, 1)))
            return ev
        # with no static friction Eq. (2) holds only where the load is exactly 0: no sticking
        if self.m.restick and mc.static > 0.0 and hy.mode is Mode.SLIDING:
            ev.append(("slow", _event(lambda t, y: abs(y[1]) - mc.stick_velocity, -1)))
        if hy.mode is Mode.CREEPING:
            ev.append(("weak", _event(lambda t, y: abs(load(t, y)) - mc.static, -1)))
            ev.append(("fast", _event(lambda t, y: abs(y[1]) - mc.stick_velocity, 1)))
        if np.isfinite(mc.q_max):
            ev.append(("stop+", _event(lambda t, y: y[0] - mc.q_max, 1)))
        if np.isfinite(mc.q_min):
            ev.append(("stop-", _event(lambda t, y: y[0] - mc.q_min, -1)))
        return ev

    def _kinetics_events(self):
        ev = []
        for i, rule in enumerate(self.hy.rules):
            s = rule.motion
            if s:  # the driving quantity turns back: its rate goes RATE_TOL the other way
                ev.append((f"turn {i}", _event(lambda t, y, i=i, s=s: s * self.driving_rate(i, t, y) + RATE_TOL, -1)))
            else:  # a still wire starts to move
                ev.append((f"start {i}", _event(lambda t, y, i=i: abs(self.driving_rate(i, t, y)) - RATE_TOL, 1)))
            for name, mark, direction in rule.marks():
                ev.append((f"{name} {i}", _event(lambda t, y, i=i, c=mark: self.level(i, t, y) - c, direction)))
        return ev


def _event(f, direction: int):
    f.terminal, f.direction = True, direction
    return f


# --------------------------------------------------------------------------------------------
# discrete updates
# --------------------------------------------------------------------------------------------
def _sign(x: float) -> int:
    return int(x > 0.0) - int(x < 0.0)


def commit(seg: _Segment, y, forced: dict[int, int] | None = None) -> None:
    """Every wire's rule commits the state y and takes the sign of its driving rate (0 within RATE_TOL).

    ``forced``: wire -> sign where the trajectory stopped because that wire's rate turned or
    started (there the rate is RATE_TOL up to the event's location).
    """
    forced = forced or {}
    d = seg.at(None, y)
    for i, (w, rule) in enumerate(zip(seg.m.wires, seg.hy.rules)):
        rate = seg.driving_rate(i, None, y)
        sign = forced.get(i, _sign(rate) if abs(rate) > RATE_TOL else 0)
        rule.update(sign, y[index("T", i, seg.n)], d.outputs[w.name + ".sigma"], d.outputs[w.name + ".xi"])


def on_event(name: str, seg: _Segment, y) -> dict[int, int]:
    """Apply the event ``name`` to the discrete state ``seg.hy`` and the state vector y.

    Returns the wires whose driving rate turned or started, with their new sign (for :func:`commit`).
    """
    hy, mc, d = seg.hy, seg.m.mechanism, seg.at(None, y)
    load = d.outputs["load"]
    forced = {}
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
    else:  # a wire's kinetics: "turn <i>", or one of its rule's marks
        kind, i = name.split()
        i = int(i)
        rule, w = hy.rules[i], seg.m.wires[i]
        if kind == "turn":
            forced[i] = -rule.motion
        elif kind == "start":
            forced[i] = _sign(seg.driving_rate(i, None, y))
        else:
            rule.on_mark(kind, y[index("T", i, seg.n)], d.outputs[w.name + ".sigma"], d.outputs[w.name + ".xi"])
    if hy.mode is Mode.STUCK:
        y[1] = 0.0
    return forced


def held_inputs(m: OracleModel, hy: Hybrid, st: Stretch, current: bool) -> Held:
    """The inputs held over a stretch: open loop, every wire's heating phase is its drive being on."""
    hot = m.damping == "heating-value" or any(st.on)
    viscous = m.mechanism.viscous_heating if hot else m.mechanism.viscous_cooling
    return Held(hy.mode is Mode.STUCK, viscous, m.initial_target, 1.0, current,
                tuple(WireHeld(dr, on, rule.held()) for dr, on, rule in zip(st.drives, st.on, hy.rules)))
