"""An open-loop run of the oracle: the program's stretches integrated by ``solve_ivp`` with events."""

from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp

from .build import build
from .program import Step, parse, stretches
from .rules import make_rule
from .trajectory import (
    MECHANISM_STATE, WIRE_STATE, Hybrid, Mode, Trajectory, _Segment, commit, held_inputs, index, on_event,
)

#: absolute tolerances per state component at rtol = 1e-6 (scaled with rtol)
_ATOL_MECHANISM = {"q": 1e-9, "v": 1e-7, "error_integral": 1e-9}  # rad or m, their rates
_ATOL_WIRE = {"T": 1e-6, "sigma": 1.0, "electrical": 1e-6, "heat": 1e-6, "T_case": 1e-6}  # degC, Pa, J
#: the per-wire signals of a trajectory: the state's, and the algebraic ones (solved at the samples)
SIGNALS = WIRE_STATE + ("xi",)


def initial_state(m) -> np.ndarray:
    """q0 at rest, each wire at T_init and its initial stress, no energy, its casing at the ambient."""
    start = {"T": [w.T_init for w in m.wires], "sigma": [w.sigma0 for w in m.wires],
             "electrical": [0.0] * len(m.wires), "heat": [0.0] * len(m.wires),
             "T_case": [w.T_amb for w in m.wires]}
    return np.array([m.mechanism.q0, 0.0, 0.0] + [v for k in WIRE_STATE for v in start[k]])


def simulate(params, program: str | list[Step], kind: str = "voltage", t_end: float = 20.0,
             method: str = "LSODA", rtol: float = 1e-8, atol=None, sample_s: float = 0.01,
             max_events: int = 10_000, outputs: bool = True) -> Trajectory:
    """Integrate an open-loop ``program`` (``"T:V_1[:V_2],..."``, read as ``kind``) from rest.

    ``params`` is a parameter set (any mechanism, any hysteresis rule; the memory rule needs
    c_A = c_M); the run starts as the engine's does (q0 at rest, each wire at T_init, xi_init
    and its initial stress, not yet moved along any branch) with the open-loop target q_F = the
    initial coordinate. Returns a :class:`Trajectory` sampled every ``sample_s`` with ``info``:
    wall_s, nfev (right-hand-side calls), calls (of solve_ivp), events (by kind).
    ``outputs = False`` skips solving sigma and xi at the samples (NaN there): the state alone.
    """
    m = build(params)
    if m.restick and m.mechanism.static > 0.0 and m.mechanism.stick_velocity <= 0.0:
        raise NotImplementedError("the oracle resticks on |q'| falling through the stick velocity: "
                                  "a stick velocity of 0 (sticking on a reversal only) is not implemented")
    n = len(m.wires)
    current = kind == "current"
    steps = parse(program, kind, n, m.V_H) if isinstance(program, str) else list(program)
    if not steps or steps[0].t > 0.0:  # off until the first step, as the engine's initial commands
        steps.insert(0, Step(0.0, (m.V_H,) * n, (0.0,) * n))
    if atol is None:
        scale = rtol / 1e-6
        atol = np.array([_ATOL_MECHANISM[k] for k in MECHANISM_STATE]
                        + [_ATOL_WIRE[k] for k in WIRE_STATE for _ in range(n)]) * scale
    y = initial_state(m)
    hy = Hybrid(Mode.SLIDING, 0, [make_rule(m.rule, w.xi_init, w.T_init, m.reversal, w.transformation)
                                  for w in m.wires])
    grid = np.round(np.arange(0.0, t_end + 0.5 * sample_s, sample_s), 12)
    rows = {"mechanism": np.full((grid.size, len(MECHANISM_STATE)), np.nan),
            "wires": np.full((grid.size, len(SIGNALS), n), np.nan)}
    info = {"nfev": 0, "calls": 0, "events": 0, "by_kind": {}}
    t0 = time.perf_counter()
    for k, st in enumerate(stretches(steps, t_end, m.pwm_period, 0.0 if current else m.V_L)):
        seg = _Segment(m, hy, held_inputs(m, hy, st, current))
        commit(seg, y)  # the drive changed: each wire's branch for the stretch, then (at the start) Eq. (2)
        if k == 0:
            _initial_stick(_Segment(m, hy, held_inputs(m, hy, st, current)), hy, y)
        t = st.t0
        while t < st.t1:
            seg = _Segment(m, hy, held_inputs(m, hy, st, current))
            named = seg.events()
            sol = solve_ivp(seg.rhs, (t, st.t1), y, method=method, rtol=rtol, atol=atol, dense_output=True,
                            events=[f for _, f in named] or None)
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp failed at t = {sol.t[-1]}: {sol.message}")
            info["nfev"] += seg.nfev
            info["calls"] += 1
            _sample(seg, sol, t, rows, grid, outputs)
            y = sol.y[:, -1].copy()
            if sol.status == 1:
                _count(info, named, sol, max_events)
                times = [te[0] if te.size else np.inf for te in sol.t_events]
                forced = on_event(named[int(np.argmin(times))][0], seg, y)
                commit(_Segment(m, hy, held_inputs(m, hy, st, current)), y, forced)
                t = sol.t[-1]
            else:
                t = st.t1
    info["wall_s"] = time.perf_counter() - t0
    mech = rows["mechanism"]
    wires = {w.name: {key: rows["wires"][:, j, i] for j, key in enumerate(SIGNALS)} for i, w in enumerate(m.wires)}
    return Trajectory(grid, mech[:, 0], mech[:, 1], mech[:, 2], wires, info)


def _count(info: dict, named, sol, max_events: int) -> None:
    info["events"] += 1
    if info["events"] > max_events:
        raise RuntimeError(f"more than {max_events} events by t = {sol.t[-1]}")
    times = [te[0] if te.size else np.inf for te in sol.t_events]
    kind = named[int(np.argmin(times))][0].split()[0]
    info["by_kind"][kind] = info["by_kind"].get(kind, 0) + 1


def _initial_stick(seg: _Segment, hy: Hybrid, y) -> None:
    """Eq. (2) at the start: held if at rest with |M_E| <= M_SF, or resting on a stop it pushes into."""
    mc = seg.m.mechanism
    load = seg.at(None, y).outputs["load"]
    side = 1 if (y[0] >= mc.q_max and load > 0.0) else -1 if (y[0] <= mc.q_min and load < 0.0) else 0
    if side or (y[1] == 0.0 and abs(load) <= mc.static):
        hy.mode, hy.stop = Mode.STUCK, side


def _sample(seg: _Segment, sol, t: float, rows, grid, outputs: bool) -> None:
    """Fill the grid rows in [t, end of ``sol``] from its dense output (later segments overwrite)."""
    sel = np.flatnonzero((grid >= t - 1e-12) & (grid <= sol.t[-1] + 1e-12))
    if not sel.size:
        return
    n = seg.n
    states = sol.sol(np.clip(grid[sel], t, sol.t[-1]))
    rows["mechanism"][sel] = states[: len(MECHANISM_STATE)].T
    for j, key in enumerate(WIRE_STATE):
        rows["wires"][sel, j, :] = states[[index(key, i, n) for i in range(n)]].T
    if not outputs:
        return
    for row, col in zip(sel, states.T):
        d = seg.at(None, col)
        for i, w in enumerate(seg.m.wires):
            rows["wires"][row, WIRE_STATE.index("sigma"), i] = d.outputs[w.name + ".sigma"]
            rows["wires"][row, len(WIRE_STATE), i] = d.outputs[w.name + ".xi"]


def simulate_baseline(params, voltage="0:8:0,6:0:0", t_end=20.0, method="RK45", rtol=1e-6, atol=None,
                      sample_s=0.01):
    """The joint's open-loop voltage run as the benchmarks time it: (t, theta [deg], info).

    ``info``: wall time [s] (the integration and the state on the grid, nothing else),
    right-hand-side calls, solve_ivp calls, events, and ``states`` (theta, omega, T per wire).
    """
    tr = simulate(params, voltage, "voltage", t_end, method, rtol, atol, sample_s, outputs=False)
    states = np.vstack([tr.q, tr.v] + [w["T"] for w in tr.wires.values()])
    return tr.t, np.degrees(tr.q), dict(tr.info, states=states)
