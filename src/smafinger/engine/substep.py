"""One sub-step: the discrete decisions at its start, the output sample, the integration.

Within a sub-step every wire's drive is constant (the PWM edges end sub-steps). At its start:
the drives (Eq. 12b), the interlock check, each wire's kinetics branch (Eqs. 9-10, minor loops)
and the stick/slip state (Eq. 2) are decided; then the state is advanced and checked.
"""

import math
from typing import NamedTuple

from numba import njit

from ..control.pid import on_time, pwm_output
from ..control.strategies import Command, opposing_wires_driven
from ..model.dynamics import at_stop_holding, end_stop, stick_slip
from ..model.heat import wire_temperature_rate
from ..model.kinetics import Branch, enter_branch, next_branch
from ..model.records import Inputs, State, WireInput, WireState
from ..model.wire import wire_stress_xi
from ..parameters.options import FrictionSticking, StressLaw
from .integrators import step
from .rhs import derivative, geometry_at
from .tuples import filled, set_item, with_field


class Counters(NamedTuple):
    status: int  #: 0 ok, 1 blow-up (NaN or Inf)
    substeps: int
    violations: int  #: sub-steps with two opposing wires driven (the interlock)
    evals: int  #: right-hand-side evaluations
    sticks: int  #: times the mechanism stuck


@njit(cache=True)
def initial_state(model):
    w = model.wires
    ws = filled(w, WireState(w[0].T_init_C, w[0].sigma0_Pa, 0.0))
    for i in range(1, len(w)):
        ws = set_item(ws, i, WireState(w[i].T_init_C, w[i].sigma0_Pa, 0.0))
    return State(model.dynamics.q0, 0.0, 0.0, ws)


@njit(cache=True)
def initial_inputs(model, current_drive):
    w = model.wires
    wi = filled(w, WireInput(0.0, False, Branch(0, w[0].xi_init, w[0].xi_init, w[0].T_init_C)))
    for i in range(1, len(w)):
        wi = set_item(wi, i, WireInput(0.0, False, Branch(0, w[i].xi_init, w[i].xi_init, w[i].T_init_C)))
    return Inputs(False, 0.0, model.dynamics.q0, 1.0, current_drive, wi)


@njit(cache=True)
def initial_commands(model):
    return filled(model.wires, Command(False, False, 0.0, model.drive.V_H_V))


@njit(cache=True, inline="always")
def _branch(wire, ws, wi, drive, heating, path, run, opts):
    """A wire's kinetics branch for the sub-step (MODEL-NOTES: the sign of dT/dt, minor loops)."""
    dT = wire_temperature_rate(wire, ws.T_C, drive, heating, run.current_drive, opts.joule_heating)
    b = wi.branch
    nb, turn = next_branch(b.branch, dT, ws.T_C, b.turn_C, wire.minor_loop_reversal_C)
    if nb != b.branch:
        # xi and sigma at the reversal: those of the state on the old branch
        sigma, xi = wire_stress_xi(wire, ws, b, path, opts.stress_law)
        return enter_branch(b, nb, turn, xi, ws.T_C, sigma, wire)
    return Branch(b.branch, b.start, b.held, turn)


@njit(cache=True, inline="always")
def _held_inputs(model, run, y, inputs, geom, cmds, s, viscous, integrating, mid, stuck):
    """(inputs, drives) for a sub-step whose midpoint is ``mid`` ticks into the PWM period."""
    low = 0.0 if run.current_drive else model.drive.V_L_V
    w = model.wires
    drives = filled(w, 0.0)
    wis = inputs.wires
    for i in range(len(w)):
        c = cmds[i]
        d = pwm_output(c.level, low, c.duty, on_time(c.duty, run.pwm_ticks), mid)
        drives = set_item(drives, i, d)
        br = _branch(w[i], y.wires[i], wis[i], d, c.heating, geom.routes[i][0], run, model.options)
        wis = set_item(wis, i, WireInput(d, c.heating, br))
    return Inputs(stuck, viscous, s.q_target, integrating, run.current_drive, wis), drives, low


@njit(cache=True, inline="always")
def _after_step(model, y, stuck):
    """Post-step constraints: a tendon cannot push (rate law), a stuck mechanism is at rest, end stops."""
    ws = y.wires
    if model.options.stress_law != StressLaw.ALGEBRAIC:
        for i in range(len(ws)):
            if ws[i].sigma_Pa < 0.0:
                ws = set_item(ws, i, WireState(ws[i].T_C, 0.0, ws[i].electrical_J))
    v = 0.0 if stuck else y.v
    q, v = end_stop(y.q, v, model.dynamics)
    return State(q, v, y.error_integral, ws)


@njit(cache=True, inline="always")
def _finite(y):
    ok = math.isfinite(y.q) and math.isfinite(y.v) and math.isfinite(y.error_integral)
    for w in y.wires:
        ok = ok and math.isfinite(w.T_C) and math.isfinite(w.sigma_Pa) and math.isfinite(w.electrical_J)
    return ok


@njit(cache=True, inline="always")
def decide(model, run, y, inputs, geom, geom_q, cmds, s, viscous, integrating, a, b, ps, first, stuck, v_prev,
           counters):
    """The discrete decisions at the start of sub-step [a, b] (ticks): drives, interlock, branches,
    stick/slip (Eq. 2), and the derivative there.

    Returns (y, inputs, geom, geom_q, stuck, v_prev, counters, k1, aux, drives).
    """
    geom = geometry_at(y.q, geom_q, geom, model)
    geom_q = y.q
    inputs, drives, low = _held_inputs(model, run, y, inputs, geom, cmds, s, viscous, integrating,
                                       0.5 * (a + b) - ps, stuck)
    if opposing_wires_driven(model.wires, drives, low) and b > a:
        counters = with_field(counters, "violations", counters.violations + 1)
    # Eq. (2) at the sub-step start; if the stick state changes, the derivative is evaluated again
    restick = model.options.friction_sticking == FrictionSticking.RESTICK
    evals = counters.evals
    for attempt in range(2):  # one call site: derivative is compiled inline once here
        k1, aux = derivative(y, inputs, model, geom)
        evals += 1
        if attempt == 1:
            break
        new_stuck = (stick_slip(stuck, first, aux.load, y.v, v_prev, model.dynamics, restick)
                     or at_stop_holding(y.q, aux.load, model.dynamics))
        if new_stuck == stuck:
            break
        if new_stuck:
            y = with_field(y, "v", 0.0)
            counters = with_field(counters, "sticks", counters.sticks + 1)
        stuck = new_stuck
        inputs = with_field(inputs, "stuck", stuck)
    return y, inputs, geom, geom_q, stuck, y.v, with_field(counters, "evals", evals), k1, aux, drives


@njit(cache=True, inline="always")
def integrate(model, run, y, inputs, geom, k1, a, b, stuck, counters):
    """Advance the state over [a, b] (ticks) and apply the post-step constraints.

    Returns (y, counters, t_fail_s); ``counters.status`` is 1 if the state is no longer finite.
    """
    if b > a:
        y, n = step(run.method, model, y, (b - a) * run.tick_s, inputs, k1, geom)
        counters = with_field(with_field(counters, "evals", counters.evals + n), "substeps", counters.substeps + 1)
    y = _after_step(model, y, stuck)
    if not _finite(y):
        return y, with_field(counters, "status", 1), b * run.tick_s
    return y, counters, 0.0
