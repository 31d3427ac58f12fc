"""An open-loop run of the oracle: the program's stretches integrated by ``solve_ivp`` with events."""

from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp

from .build import build
from .material import Kinetics, Phase
from .program import Step, parse, stretches
from .trajectory import Hybrid, Mode, Trajectory, _held, _on_event, _Segment, _switch_branches

#: absolute tolerances per state component at rtol = 1e-6 (scaled with rtol):
#: q [rad or m], v, error integral, then per wire T [degC], sigma [Pa], energy [J]
_ATOL = (1e-9, 1e-7, 1e-9, 1e-6, 1.0, 1e-6)


def simulate(params, program: str | list[Step], kind: str = "voltage", t_end: float = 20.0,
             method: str = "LSODA", rtol: float = 1e-8, atol=None, sample_s: float = 0.01,
             max_events: int = 10_000, outputs: bool = True) -> Trajectory:
    """Integrate an open-loop ``program`` (``"T:V_1[:V_2],..."``, read as ``kind``) from rest.

    ``params`` is a parameter set (any mechanism); the run starts as the engine's does (q0 at
    rest, each wire at T_init, xi_init and its initial stress, on the hold branch) with the
    open-loop target q_F = the initial coordinate. Returns a :class:`Trajectory` sampled every
    ``sample_s`` with ``info``: wall_s, nfev (right-hand-side calls), calls (of solve_ivp), events.
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
    rev = params.minor_loop_reversal_C
    if atol is None:
        a = np.array(_ATOL) * (rtol / 1e-6)
        atol = np.concatenate([a[:3], np.repeat(a[3:], n)])
    y = np.array([m.mechanism.q0, 0.0, 0.0] + [w.T_init for w in m.wires] + [w.sigma0 for w in m.wires] + [0.0] * n)
    hy = Hybrid(Mode.SLIDING, 0, [Kinetics(Phase.HOLD, w.xi_init, w.xi_init) for w in m.wires],
                [w.T_init for w in m.wires])
    grid = np.round(np.arange(0.0, t_end + 0.5 * sample_s, sample_s), 12)
    rows = np.full((grid.size, 3 + 4 * n), np.nan)  # q, v, E, then T, sigma, xi, energy per wire
    info = {"nfev": 0, "calls": 0, "events": 0}
    t0 = time.perf_counter()
    for k, st in enumerate(stretches(steps, t_end, m.pwm_period, 0.0 if current else m.V_L)):
        seg = _Segment(m, hy, _held(m, hy, st, current), rev)
        if k == 0:
            _initial_stick(seg, hy, y)
            seg = _Segment(m, hy, _held(m, hy, st, current), rev)
        _switch_branches(seg, y, rev)
        t = st.t0
        while t < st.t1:
            seg = _Segment(m, hy, _held(m, hy, st, current), rev)
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
                info["events"] += 1
                if info["events"] > max_events:
                    raise RuntimeError(f"more than {max_events} events by t = {sol.t[-1]}")
                times = [te[0] if te.size else np.inf for te in sol.t_events]
                _on_event(named[int(np.argmin(times))][0], seg, y)
                t = sol.t[-1]
            else:
                t = st.t1
    info["wall_s"] = time.perf_counter() - t0
    wires = {w.name: {key: rows[:, 3 + j * n + i] for j, key in enumerate(("T", "sigma", "xi", "energy"))}
             for i, w in enumerate(m.wires)}
    return Trajectory(grid, rows[:, 0], rows[:, 1], rows[:, 2], wires, info)


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
    rows[sel, : 3 + n] = states[: 3 + n].T  # q, v, error integral, T
    rows[sel, 3 + 3 * n:] = states[3 + 2 * n:].T  # energy
    if not outputs:
        return
    for j, col in zip(sel, states.T):
        d = seg.at(None, col)
        for i, w in enumerate(seg.m.wires):
            rows[j, 3 + n + i] = d.outputs[w.name + ".sigma"]
            rows[j, 3 + 2 * n + i] = d.outputs[w.name + ".xi"]


def simulate_baseline(params, voltage="0:8:0,6:0:0", t_end=20.0, method="RK45", rtol=1e-6, atol=None,
                      sample_s=0.01):
    """The joint's open-loop voltage run as the benchmarks time it: (t, theta [deg], info).

    ``info``: wall time [s] (the integration and the state on the grid, nothing else),
    right-hand-side calls, solve_ivp calls, events, and ``states`` (theta, omega, T per wire).
    """
    tr = simulate(params, voltage, "voltage", t_end, method, rtol, atol, sample_s, outputs=False)
    states = np.vstack([tr.q, tr.v] + [w["T"] for w in tr.wires.values()])
    return tr.t, np.degrees(tr.q), dict(tr.info, states=states)
