"""One sub-step: the discrete decisions at its start, the output sample, the integration.

Within a sub-step every wire's drive is constant (the PWM edges end sub-steps). At its start:
the drives (Eq. 12b), the interlock check, each wire's kinetics branch (Eqs. 9-10, minor loops)
and the stick/slip state (Eq. 2) are decided; then the state is advanced and checked.
"""

import math
from typing import NamedTuple

from ..control.pid import on_time, pwm_output
from ..control.strategies import Command, opposing_wires_driven
from ..jit import njit
from ..model.dynamics import at_stop_holding, end_stop, stick_slip
from ..model.hysteresis import AUTHORS2020, DEADBAND, MEMORY, drive_direction, initial_record, update_memory
from ..model.hysteresis_authors import initial_calls_record
from ..model.records import Inputs, State, WireInput, WireState
from ..model.wire import algebraic_stress_rate, transformation_catch_up
from ..parameters.options import FrictionSticking, Hysteresis, StressLaw
from .authors import Stages, call_branches, commit_calls
from .clock import TICKS_PER_S
from .integrators import Method, step
from .pwm import PwmModel, averaged_drive, sampled_drive
from .dense import zero_aux
from .rhs import derivative_redone, geometry_at
from .tuples import filled, set_item, with_field


#: ``Counters.status``: the run went on to its end; the state became NaN or Inf (a blow-up);
#: the controller commanded a duty that is no number (it read a sensor it did not declare, or
#: its own arithmetic failed: the wire would silently stay off)
STATUS_OK, STATUS_BLOWUP, STATUS_BAD_DUTY = 0, 1, 2


class Counters(NamedTuple):
    status: int  #: STATUS_OK, STATUS_BLOWUP or STATUS_BAD_DUTY
    substeps: int
    violations: int  #: sub-steps with two opposing wires driven (the interlock)
    evals: int  #: right-hand-side evaluations
    sticks: int  #: times the mechanism stuck


#: rows of each wire's reversal-point stack (return-point memory; merges beyond, docs/hysteresis.md)
STACK_CAPACITY = 64


@njit(cache=True)
def initial_state(model):
    w = model.wires
    ws = filled(w, WireState(0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    for i in range(len(w)):
        ws = set_item(ws, i, WireState(w[i].T_init_C, w[i].sigma0_Pa, 0.0, 0.0, w[i].T_amb_C, w[i].xi_init))
    return State(model.dynamics.q0, 0.0, 0.0, ws)


@njit(cache=True)
def _initial_branch(wire, rule):
    """A wire at rest on its kinetics branch (model.hysteresis), with the rule's dead band."""
    if rule == Hysteresis.DEADBAND:
        rec, _ = initial_record(DEADBAND, wire.xi_init, wire.T_init_C, wire.minor_loop_reversal_C)
        return rec
    code = AUTHORS2020 if rule == Hysteresis.AUTHORS2020 else MEMORY
    rec, _ = initial_record(code, wire.xi_init, wire.T_init_C, 0.0)
    return rec


@njit(cache=True)
def initial_inputs(model, current_drive):
    w = model.wires
    rule = model.options.hysteresis
    wi = filled(w, WireInput(0.0, False, _initial_branch(w[0], rule), 0))
    for i in range(1, len(w)):
        wi = set_item(wi, i, WireInput(0.0, False, _initial_branch(w[i], rule), 0))
    return Inputs(False, 0.0, model.dynamics.q0, 1.0, current_drive, wi)


@njit(cache=True)
def authors_calls_inputs(inputs, model):
    """``inputs`` for the authors' solver: a wire on the authors2020 rule gets their martensite
    functions' globals (:func:`~smafinger.model.hysteresis_authors.initial_calls_record`)."""
    wis = inputs.wires
    for i in range(len(wis)):
        wi = wis[i]
        if wi.branch.rule == AUTHORS2020:
            rec = initial_calls_record(model.wires[i].xi_init)
            wis = set_item(wis, i, WireInput(wi.drive, wi.heating, rec, wi.depth))
    return with_field(inputs, "wires", wis)


@njit(cache=True)
def initial_commands(model):
    return filled(model.wires, Command(False, False, 0.0, model.drive.V_H_V))


@njit(cache=True, forceinline=True)
def _branch_moved(a, b):
    """Did a memory update change how xi is evaluated (not only the extreme reached so far)?"""
    return not (a.direction == b.direction and a.x0 == b.x0 and a.g0 == b.g0 and a.slope == b.slope
                and a.target_tau == b.target_tau and a.parent_slope == b.parent_slope)


@njit(cache=True, forceinline=True)
def _any(flags):
    """True if any item of the tuple of bools ``flags`` is."""
    out = False
    for f in flags:
        out = out or f
    return out


@njit(cache=True, forceinline=True)
def _update_kinetics(model, y, inputs, geom, k1, aux, stacks):
    """Each wire's kinetics branch for the sub-step, from the derivatives at its start (Eqs. 9-10).

    The direction (tau = T - sigma/c rising, falling or neither; the legacy rules: the sign of
    dT/dt) comes from k1: the stress rate of the state under the rate law, that of the solved
    stress under the algebraic law (:func:`~smafinger.model.wire.algebraic_stress_rate`; the
    state's is 0 there); the memory commits the wipe-outs and reversals at the current point.
    Returns (inputs, moved): ``moved[i]`` if wire i's branch must be evaluated anew.
    """
    wis = inputs.wires
    moved = filled(wis, False)
    algebraic = model.options.stress_law == StressLaw.ALGEBRAIC
    for i in range(len(wis)):
        wi = wis[i]
        wire = model.wires[i]
        dsigma = k1.wires[i].sigma_Pa
        if algebraic and wi.branch.rule == MEMORY:  # the legacy rules read dT/dt alone
            dsigma = algebraic_stress_rate(wire, y.wires[i].T_C, aux.wires[i].sigma_Pa, wi.branch,
                                           k1.wires[i].T_C, geom.routes[i].dpath_dq * y.v)
        d = drive_direction(wi.branch, k1.wires[i].T_C, dsigma, wire)
        rec, depth = update_memory(wi.branch, stacks[i], wi.depth, y.wires[i].T_C, aux.wires[i].sigma_Pa, d,
                                   wire)
        moved = set_item(moved, i, _branch_moved(wi.branch, rec))
        wis = set_item(wis, i, WireInput(wi.drive, wi.heating, rec, depth))
    return with_field(inputs, "wires", wis), moved


@njit(cache=True, forceinline=True)
def _drive(run, c, low, phase):
    """A wire's drive under command ``c`` at ``phase`` ticks into the PWM period (:mod:`.pwm`).

    ``exact``: the wave at ``phase`` ticks (a sub-step's midpoint; sub-steps end at the edges);
    ``averaged``: the period's RMS level; ``sampled``: the wave read ``phase`` seconds after the
    period's reference time, as the authors' solver reads it (:func:`.pwm.sampled_phases`).
    """
    if run.pwm == PwmModel.AVERAGED:
        return averaged_drive(c.level, low, c.duty)
    if run.pwm == PwmModel.SAMPLED:
        return sampled_drive(c.level, low, c.duty, on_time(c.duty, run.pwm_ticks / TICKS_PER_S), phase)
    return pwm_output(c.level, low, c.duty, on_time(c.duty, run.pwm_ticks), phase)


@njit(cache=True, forceinline=True)
def _low(model, run):
    """The drive between PWM pulses: V_L, or 0 A with a current drive."""
    return 0.0 if run.current_drive else model.drive.V_L_V


@njit(cache=True, forceinline=True)
def _held_inputs(model, run, y, inputs, geom, cmds, s, viscous, integrating, phase, stuck):
    """(inputs, drives, interlock drives) for a sub-step; ``phase``: where the drive is read.

    The interlock drives are the resolved wave's: the sub-step's own with the exact PWM, the
    levels at the period start (where every wire with a duty above 0 is on) otherwise.
    """
    low = _low(model, run)
    w = model.wires
    drives = filled(w, 0.0)
    resolved = filled(w, 0.0)
    wis = inputs.wires
    for i in range(len(w)):
        c = cmds[i]
        d = _drive(run, c, low, phase)
        drives = set_item(drives, i, d)
        if run.pwm != PwmModel.EXACT:
            d = pwm_output(c.level, low, c.duty, on_time(c.duty, run.pwm_ticks), 0.0)
        resolved = set_item(resolved, i, d)
        wis = set_item(wis, i, WireInput(drives[i], c.heating, wis[i].branch, wis[i].depth))
    return Inputs(stuck, viscous, s.q_target, integrating, run.current_drive, wis), drives, resolved, low


@njit(cache=True, forceinline=True)
def _after_step(model, y, stuck):
    """Post-step constraints: a tendon cannot push (rate law), a stuck mechanism is at rest, end stops."""
    ws = y.wires
    if model.options.stress_law != StressLaw.ALGEBRAIC:
        for i in range(len(ws)):
            if ws[i].sigma_Pa < 0.0:
                ws = set_item(ws, i, with_field(ws[i], "sigma_Pa", 0.0))
    v = 0.0 if stuck else y.v
    q, v = end_stop(y.q, v, model.dynamics)
    return State(q, v, y.error_integral, ws)


@njit(cache=True, forceinline=True)
def _xi_restarted(y, aux):
    """y with each wire's ``xi_integrated`` restarted at its xi (the sub-step start's, ``aux``)."""
    ws = y.wires
    for i in range(len(ws)):
        ws = set_item(ws, i, with_field(ws[i], "xi_integrated", aux.wires[i].xi))
    return State(y.q, y.v, y.error_integral, ws)


@njit(cache=True, forceinline=True)
def _xi_caught_up(model, y, inputs):
    """y with each wire's stress caught up with its transformation over the sub-step (rate law,
    :func:`~smafinger.model.wire.transformation_catch_up`)."""
    if model.options.stress_law == StressLaw.ALGEBRAIC:
        return y
    ws = y.wires
    for i in range(len(ws)):
        sigma, xi = transformation_catch_up(model.wires[i], ws[i], inputs.wires[i].branch)
        ws = set_item(ws, i, with_field(with_field(ws[i], "sigma_Pa", sigma), "xi_integrated", xi))
    return State(y.q, y.v, y.error_integral, ws)


#: the physical range of the state: outside it a run has blown up even while its numbers are
#: finite (an explicit step beyond its stability limit grows for a long time before it
#: overflows: found by review, joint angles of 1e14 deg returned as a result; an unstable
#: casing node swung to -2,412 degC). Temperatures [degC] from absolute zero to far above
#: NiTi's melting point (1,310 degC); the coordinate [rad or m] within 1,000 (57,000 deg, a
#: kilometre of travel).
T_MIN_C, T_MAX_C, Q_MAX = -273.15, 1.0e4, 1.0e3


@njit(cache=True, forceinline=True)
def _in_range(T_C):
    return T_MIN_C <= T_C <= T_MAX_C  # False for NaN


@njit(cache=True, forceinline=True)
def _finite(y):
    """The state is finite and inside its physical range (:data:`T_MIN_C`, :data:`T_MAX_C`,
    :data:`Q_MAX`)."""
    ok = abs(y.q) <= Q_MAX and math.isfinite(y.v) and math.isfinite(y.error_integral)
    for w in y.wires:
        ok = (ok and _in_range(w.T_C) and math.isfinite(w.sigma_Pa) and math.isfinite(w.electrical_J)
              and _in_range(w.T_case_C))
    return ok


@njit(cache=True, forceinline=True)
def _aux_finite(aux):
    """The algebraic quantities are finite: the load and each wire's stress and xi (under the
    algebraic law the stress is solved, not a state, and can fail while the state stays finite:
    found by review, NaN recorded in 999 of 1,001 samples without an error)."""
    ok = math.isfinite(aux.load)
    for w in aux.wires:
        ok = ok and math.isfinite(w.sigma_Pa) and math.isfinite(w.xi)
    return ok


@njit(cache=True, forceinline=True)
def decide(model, run, y, inputs, geom, geom_q, cmds, s, viscous, integrating, a, b, phase, first, stuck, v_prev,
           counters, stacks):
    """The discrete decisions at the start of sub-step [a, b] (ticks): drives, interlock, kinetics
    branches (Eqs. 9-10), stick/slip (Eq. 2), and the derivative there. ``phase``: where the
    PWM is read (:func:`_drive`).

    Returns (y, inputs, geom, geom_q, stuck, v_prev, counters, k1, aux, drives).
    """
    geom = geometry_at(y.q, geom_q, geom, model)
    geom_q = y.q
    inputs, drives, resolved, low = _held_inputs(model, run, y, inputs, geom, cmds, s, viscous, integrating,
                                                 phase, stuck)
    if opposing_wires_driven(model.wires, resolved, low) and b > a:
        counters = with_field(counters, "violations", counters.violations + 1)
    # the derivative at the sub-step start; then the kinetics branches and Eq. (2) are decided from
    # it, and whenever a decision changes what the derivative depends on it is evaluated again
    # (only the wires whose branch moved are evaluated again: the others' terms are unchanged)
    restick = model.options.friction_sticking == FrictionSticking.RESTICK
    evals = counters.evals
    kinetics_done = False
    stick_done = False
    calls = run.method == Method.AUTHORS_ODE4  # the authors' martensite calls (rule AUTHORS_CALLS)
    if calls:
        inputs = call_branches(model, y, inputs)
    redo = filled(model.wires, True)
    k1, aux = State(0.0, 0.0, 0.0, filled(y.wires, WireState(0.0, 0.0, 0.0, 0.0, 0.0, 0.0))), zero_aux(model.wires)
    for _ in range(3):  # one call site: derivative is compiled inline once here
        k1, aux = derivative_redone(y, inputs, model, geom, (k1, aux), redo)
        evals += 1
        if not kinetics_done:
            kinetics_done = True
            if calls:
                inputs = commit_calls(model, y, inputs, aux)
            inputs, redo = _update_kinetics(model, y, inputs, geom, k1, aux, stacks)
            if _any(redo):
                continue
        redo = filled(model.wires, True)  # a stick/slip change: v and the mechanism's rates
        if stick_done:
            break
        stick_done = True
        new_stuck = (stick_slip(stuck, first, aux.load, y.v, v_prev, model.dynamics, restick)
                     or at_stop_holding(y.q, aux.load, model.dynamics))
        if new_stuck == stuck:
            break
        if new_stuck:
            y = with_field(y, "v", 0.0)
            counters = with_field(counters, "sticks", counters.sticks + 1)
        stuck = new_stuck
        inputs = with_field(inputs, "stuck", stuck)
    y = _xi_restarted(y, aux)
    return y, inputs, geom, geom_q, stuck, y.v, with_field(counters, "evals", evals), k1, aux, drives


@njit(cache=True, forceinline=True)
def integrate(model, run, y, inputs, geom, k1, aux, a, b, stuck, counters, cmds, s, phase_mid, phase_end,
              error_major, damp):
    """Advance the state over [a, b] (ticks) and apply the post-step constraints (``k1``, ``aux``:
    the derivative and the algebraic quantities at the start).

    With the authors' solver the later stages read the controller and the PWM at their own
    states and phases (``phase_mid``, ``phase_end``; ``cmds``: the tick's commands, ``s``: the
    schedule, ``error_major``: q_F - q at the major step; see :func:`.authors.stage_inputs`). Returns (y, counters,
    t_fail_s, inputs, damp); ``counters.status`` is 1 if the algebraic quantities at the start
    are not finite (``t_fail_s`` the start) or the state after the step is not, or is out of its physical
    range (:func:`_finite`; ``t_fail_s`` the end); ``inputs`` carry the
    authors' martensite globals after the step; ``damp``: the exponential integrator's factors, kept
    for the next step (:func:`.integrators.step`).
    """
    if not _aux_finite(aux):
        return y, with_field(counters, "status", STATUS_BLOWUP), a * run.tick_s, inputs, damp
    if b > a:
        stages = Stages(run, cmds, s.enabled, s.q_target, _low(model, run), phase_mid, phase_end, error_major)
        y, n, inputs, damp = step(run.method, model, y, (b - a) * run.tick_s, inputs, k1, aux, geom, stages, damp)
        y = _xi_caught_up(model, y, inputs)
        counters = with_field(with_field(counters, "evals", counters.evals + n), "substeps", counters.substeps + 1)
    y = _after_step(model, y, stuck)
    if not _finite(y):
        return y, with_field(counters, "status", STATUS_BLOWUP), b * run.tick_s, inputs, damp
    return y, counters, 0.0, inputs, damp
