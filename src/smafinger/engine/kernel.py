"""The compiled fixed-step simulation loop: schedule, control tick, sub-steps, record.

Time runs on an integer clock of ``tick_s`` seconds (1 ns): step ends, PWM period starts,
controller updates, output samples and target changes fall on exact integer ticks, so no time
drifts from adding dt. Within a step, the PWM duty edges (period start + t_DC, Eq. 12b) split
the step, so that each sub-step sees a constant drive: the edges are resolved exactly whatever
the step size. With a PWM model other than ``exact`` (:mod:`.pwm`) the drive is constant over
a step without splitting it, and steps do not end at output samples either: the samples between
two sub-step starts are interpolated (:mod:`.dense`).

At every sub-step start the discrete state is updated (:mod:`.substep`): drives, kinetics
branches, stick/slip; the interlock is checked (two opposing wires driven at once counts as a
violation). The loop itself only sequences these.
"""

import math
from typing import NamedTuple

import numpy as np

from ..control.controller import program_commands, viscous_coefficient
from ..control.interface import control_tick, initial_control_state
from ..control.pid import pwm_edge
from ..control.strategies import Strategy
from ..jit import njit
from ..model.hysteresis_memory import STACK_COLUMNS
from ..parameters.options import IntegralReset
from .authors import NO_MAJOR_STEP, DerivativeMemory, major_commands
from .dense import interpolated, zero_aux
from .pwm import PwmModel, sampled_phases
from .rhs import geometry, geometry_at
from .schedule import Schedule, advance, confirm_tick, track_reach
from .signals import record_sample
from .integrators import NO_DAMPING, Method
from .substep import (STACK_CAPACITY, STATUS_BAD_DUTY, Counters, authors_calls_inputs, decide, initial_commands,
                      initial_inputs, initial_state, integrate)
from .tuples import filled, with_field
from .unmanaged import unmanaged


class RunSettings(NamedTuple):
    """A run's settings in kernel form (times in integer ticks)."""

    strategy: Strategy
    method: int  #: integrators.Method
    wait_release: bool  #: independent strategy: wait for the previous agonist to cool
    current_drive: bool  #: the drive levels are currents [A], not voltages
    tick_s: float
    dt_ticks: int
    t_end_ticks: int
    out_ticks: int
    update_ticks: int  #: controller update interval (0: every sub-step)
    pwm_ticks: int
    tol: float  #: a target is reached within this (rad or m)...
    hold_ticks: int  #: ...for this long
    pwm: int = PwmModel.EXACT  #: pwm.PwmModel: how the drive is applied
    every_signal: bool = True  #: record every signal, else only signals.METRIC_FIELDS


class Program(NamedTuple):
    """Open loop: from ``ticks[k]`` on, wire i is driven at ``level[k, i]`` with duty ``duty[k, i]`` %."""

    ticks: object  #: int64[n]
    level: object  #: float64[n, n_wires]
    duty: object  #: float64[n, n_wires]


def memory_stacks(n_wires: int) -> np.ndarray:
    """The kernel's scratch for each wire's reversal-point stack (return-point memory), zeros."""
    return np.zeros((n_wires, STACK_CAPACITY, STACK_COLUMNS))


@njit(cache=True, forceinline=True)
def _interval_end(t, run, cmds, next_event):
    """End of the interval that starts at tick t: the next step, PWM period, sample, update or event."""
    ps = (t // run.pwm_ticks) * run.pwm_ticks
    t_next = min(((t // run.dt_ticks) + 1) * run.dt_ticks, run.t_end_ticks)
    if run.pwm == PwmModel.EXACT:
        for c in cmds:
            if 0.0 < c.duty < 100.0:  # a duty strictly inside (0, 100) %: split at every period start
                t_next = min(t_next, ps + run.pwm_ticks)
        t_next = min(t_next, ((t // run.out_ticks) + 1) * run.out_ticks)  # else: samples interpolated
    if run.update_ticks > 0:
        t_next = min(t_next, ((t // run.update_ticks) + 1) * run.update_ticks)
    if next_event > t:
        t_next = min(t_next, next_event)
    return t_next


@njit(cache=True, forceinline=True)
def _sub_bounds(t, t_next, ps, cmds, run, bounds):
    """Fill ``bounds`` with the sub-step ends in (t, t_next]: the PWM duty edges (exact PWM), then t_next."""
    nb = 0
    for c in cmds:
        if run.pwm != PwmModel.EXACT:
            break
        e = pwm_edge(ps, c.duty, run.pwm_ticks)
        if not (e > t and e < t_next):
            continue
        k = nb  # insertion sort, duplicates dropped
        while k > 0 and bounds[k - 1] > e:
            k -= 1
        if k > 0 and bounds[k - 1] == e:
            continue
        for m in range(nb, k, -1):
            bounds[m] = bounds[m - 1]
        bounds[k] = e
        nb += 1
    bounds[nb] = t_next
    return nb + 1


@njit(cache=True, forceinline=True)
def _flush(mo, wo, out_i, next_out, run, wires, a, final, prev, now):
    """Write the output samples due before sub-step start ``a`` (and at ``a`` on the final pass).

    ``prev`` and ``now`` are (tick, state, aux, cmds, drives, stuck, q_target, segment, geometry)
    at the previous sub-step start and at ``a``. A sample at ``prev``'s tick takes its values, one
    in between interpolates the state (:func:`.dense.interpolated`) and keeps ``prev``'s tendon
    geometry (for the wire resistance); one at ``a`` takes ``now``'s. With the exact PWM every
    sample falls on a sub-step start. Returns (out_i, next_out).
    """
    n_out = mo.shape[1]
    while out_i < n_out and (next_out < a or (final and next_out == a)):
        src = now if next_out == a else prev
        y, aux = src[1], src[2]
        if next_out != a and next_out != prev[0]:
            y, aux = interpolated(prev[1], prev[2], now[1], now[2], (next_out - prev[0]) / (a - prev[0]))
        record_sample(mo, wo, out_i, float(next_out) * run.tick_s, y, aux, src[6], src[7], src[5], src[3], src[4],
                      wires, src[8], run.every_signal)
        out_i += 1
        next_out += run.out_ticks
    return out_i, next_out


@njit(cache=True, forceinline=True)
def _segment_due(s, t, seg_start):
    """A segment starts at t (its time has come, or its predecessor's target was reached)."""
    if s.next_seg >= len(seg_start):
        return False
    st = seg_start[s.next_seg]
    return (st >= 0 and st <= t) or (st < 0 and s.confirmed)


@njit(cache=True)
def _next_event(s, run, segs, prog, prog_i):
    """The next scheduled change after now: a segment start or a program step (-1: none)."""
    e = -1
    if s.next_seg < len(segs.start) and segs.start[s.next_seg] >= 0:
        e = segs.start[s.next_seg]
    if run.strategy == Strategy.OPEN_LOOP and prog_i < len(prog.ticks):
        e = prog.ticks[prog_i] if e < 0 else min(e, prog.ticks[prog_i])
    return e


@njit(cache=True, forceinline=True)
def _initial_run(model, run):
    """(state, inputs, commands) at t = 0; with the authors' solver, their martensite functions' globals."""
    inputs = initial_inputs(model, run.current_drive)
    if run.method == Method.AUTHORS_ODE4:
        inputs = authors_calls_inputs(inputs, model)
    return initial_state(model), inputs, initial_commands(model)


@njit(cache=True, forceinline=True)
def _control(model, run, t, s, y, inputs, geom, geom_q, cmds, integrating, ctl, memory, started):
    """The closed-loop controller's tick at t (its period, every sub-step, or a segment start);
    with the authors' solver, their PID's error rate from their Derivative block
    (:func:`.authors.major_commands`). Returns (commands, integrating, controller state)."""
    if started or run.update_ticks == 0 or t % run.update_ticks == 0:
        cmds, integrating, ctl = control_tick(model.controller, ctl, model, s, y, inputs, geom, geom_q,
                                              t * run.tick_s, started)
        if run.pwm == PwmModel.SAMPLED:
            cmds, integrating = major_commands(model, run, t, s, y, cmds, integrating, memory)
    return cmds, integrating, ctl


@njit(cache=True, forceinline=True)
def _duties_finite(cmds):
    """Every commanded duty is a number (a NaN duty would leave its wire off without a word)."""
    ok = True
    for c in cmds:
        ok = ok and math.isfinite(c.duty)
    return ok


@njit(cache=True, forceinline=True)
def _advance(s, t, segs, seg_actual, seg_reached, run, model, y, inputs, geom):
    """The schedule at tick t (:func:`.schedule.advance`), with a target met at its segment's
    start entered there, not at the first step's end (found by review: reached a step late, and
    every reach segment after it started a step late). Returns (schedule, started)."""
    s, started = advance(s, t, segs, seg_actual, run.strategy, run.wait_release, model, y, inputs, geom)
    if started and s.band_since < 0:
        s, reached = track_reach(s, t, y.q, run.tol, run.hold_ticks, t, y.q, False)
        if reached >= 0:
            seg_reached[s.next_seg - 1] = reached
    return s, started


@njit(cache=True, forceinline=True)
def _step_event(s, run, t, next_event, locate):
    """The next event a step must end at: the scheduled one or, with long steps (``locate``), the
    tick at which the target will count as reached if that comes first."""
    if locate:
        c = confirm_tick(s, run.hold_ticks)
        if c > t and (next_event <= t or c < next_event):
            return c
    return next_event


@njit(cache=True, nogil=True)
def run_kernel(model, run, segs, prog, mech_out, wire_out, seg_actual, seg_reached, memory_scratch):
    """Simulate from t = 0 to t_end; fill the output arrays (one row per output sample).

    ``mech_out`` (mechanism fields x samples) and ``wire_out`` (wires x wire fields x samples) are
    written by row (``signals.MC``, ``signals.WC``). ``seg_reached[k]`` becomes the tick at
    which segment k's target was entered for good (within ``run.tol`` for ``run.hold_ticks``), -1 if
    never. Returns (counters, state, t_fail_s): if the state became NaN or Inf, ``counters.status``
    is 1 and ``state`` is the state at ``t_fail_s``. ``memory_scratch``: the wires' reversal points
    (:func:`memory_stacks`). It and the outputs go on as views without reference counts (:mod:`.unmanaged`).
    """
    y, inputs, cmds = _initial_run(model, run)
    ctl = initial_control_state(model.controller, model)  # the controller's own state (control.interface)
    s = Schedule(0, model.dynamics.q0, 0, -1, False, -1, -1, -1, False)
    geom, geom_q = geometry(model, y.q), y.q
    counters = Counters(0, 0, 0, 0, 0)
    bounds = np.empty(len(model.wires) + 1)
    stacks, mo, wo = unmanaged(memory_scratch), unmanaged(mech_out), unmanaged(wire_out)  # the caller owns them
    n_out = mech_out.shape[1]
    prev = (-1, y, zero_aux(model.wires), cmds, filled(model.wires, 0.0), False, s.q_target, -1, geom)
    integrating = 1.0
    pwm_ref = 0.0  #: the sampled PWM's period reference time [s] (pwm.sampled_phases)
    memory = NO_MAJOR_STEP  #: the authors' Derivative block's last major step (authors.major_commands)
    locate = run.pwm == PwmModel.AVERAGED  #: long steps: reach events located inside a step
    t, prog_i, next_out, out_i = 0, 0, 0, 0
    first, stuck, v_prev = True, False, 0.0
    damp = NO_DAMPING  #: the exponential integrator's phi1, phi2, kept while -c h repeats
    next_event = _next_event(s, run, segs, prog, prog_i)
    while True:
        if _segment_due(s, t, segs.start) or s.waiting:
            geom = geometry_at(y.q, geom_q, geom, model)
            geom_q = y.q
            s, started = _advance(s, t, segs, seg_actual, seg_reached, run, model, y, inputs, geom)
            next_event = _next_event(s, run, segs, prog, prog_i)
        else:
            started = False
        if started and model.options.integral_reset == IntegralReset.SEGMENT:
            y = with_field(y, "error_integral", 0.0)
        if run.strategy == Strategy.OPEN_LOOP:
            if prog_i < len(prog.ticks) and prog.ticks[prog_i] <= t:
                while prog_i < len(prog.ticks) and prog.ticks[prog_i] <= t:
                    prog_i += 1
                cmds = program_commands(cmds, prog.level[prog_i - 1], prog.duty[prog_i - 1])
                next_event = _next_event(s, run, segs, prog, prog_i)
        else:
            cmds, integrating, ctl = _control(model, run, t, s, y, inputs, geom, geom_q, cmds, integrating, ctl,
                                              memory, started)
            if not _duties_finite(cmds):
                return with_field(counters, "status", STATUS_BAD_DUTY), y, t * run.tick_s
        if run.pwm == PwmModel.SAMPLED:  # their Derivative block's update, after its output
            memory = DerivativeMemory(s.q_target - y.q, t)
        viscous = viscous_coefficient(model.dynamics, cmds, model.options.damping_switch)
        t_next = _interval_end(t, run, cmds, _step_event(s, run, t, next_event, locate))
        t_start, q_start = t, y.q
        ps = (t // run.pwm_ticks) * run.pwm_ticks
        a = float(t)
        for j in range(_sub_bounds(t, t_next, ps, cmds, run, bounds)):
            b = bounds[j]
            phase, phase_mid, phase_end = 0.5 * (a + b) - ps, 0.0, 0.0
            if run.pwm == PwmModel.SAMPLED:
                phase, phase_mid, phase_end, pwm_ref = sampled_phases(a, b, run.dt_ticks, run.pwm_ticks, pwm_ref)
            y, inputs, geom, geom_q, stuck, v_prev, counters, k1, aux, drives = decide(
                model, run, y, inputs, geom, geom_q, cmds, s, viscous, integrating, a, b, phase, first, stuck,
                v_prev, counters, stacks)
            first = False
            now = (int(a), y, aux, cmds, drives, stuck, s.q_target, s.next_seg - 1, geom)
            final = t >= run.t_end_ticks
            if out_i < n_out and (next_out < a or (final and next_out == a)):
                out_i, next_out = _flush(mo, wo, out_i, next_out, run, model.wires, a, final, prev, now)
            prev = now
            y, counters, t_fail, inputs, damp = integrate(model, run, y, inputs, geom, k1, aux, a, b, stuck, counters,
                                                          cmds, s, phase_mid, phase_end, memory.error, damp)
            if counters.status != 0:
                return counters, y, t_fail
            a = b
        if t >= run.t_end_ticks:
            break
        t = t_next
        s, reached = track_reach(s, t, y.q, run.tol, run.hold_ticks, t_start, q_start, locate)
        if reached >= 0:
            seg_reached[s.next_seg - 1] = reached
        if t >= run.t_end_ticks and out_i >= n_out:
            break  # else: one more pass records the samples still due
    return counters, y, 0.0
