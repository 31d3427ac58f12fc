"""The authors' Simulink solver (``authors-ode4``): what each evaluation of their model sees.

Their model (``Code/Finger_Full_Model.mdl`` in gabrielegilardi/FingerControl; MODEL-NOTES,
"Details of the authors' 2020 model") is solved by ode4 at a fixed 1 ms step (its
``Simulink.SolverCC``: ``Solver "ode4"``, ``FixedStep "0.001"``). ode4 evaluates the model's
outputs at the major time t_n and at its three later stages, t_n + h/2 (twice) and t_n + h,
and each of these evaluations runs the control blocks:

- the PID (Eq. 12a) in the MATLAB function ``SMA1_Control_Signal.m`` / ``SMA2_Control_Signal.m``
  (``MATLABFcn`` blocks "SMA1 Control Signal" / "Control Signal 2", no sample time set: they
  inherit the continuous rate of their inputs), re-evaluated at every call since their
  sampling times are 0 (``dtCtrl_H = dtCtrl_C = 0``, ``Initialization.m``);
- its error rate d(theta_F - theta)/dt from a Simulink ``Derivative`` block ("SMA1 Controller"
  / "SMA2 Controller", SIDs 12 and 36), not from the joint's velocity: the block divides the
  change of its input since the last *major* step by the time since it
  (:func:`derivative_block`), so at t_n it is the backward difference over the step just
  taken, at the stages the difference from t_n;
- the PWM wave read at the call's time (:func:`.pwm.sampled_phases`).

- their martensite-fraction functions called once per evaluation, the branch from that
  evaluation's dT/dt, their globals changed by every call
  (:mod:`smafinger.model.hysteresis_authors`): :func:`call_branches` before an evaluation,
  :func:`commit_calls` after it.

:func:`stage_inputs` builds a later stage's inputs; :func:`major_commands` the major step's.
A run with a controller period, or an open-loop program, keeps the commands of its tick at the
stages and only reads the PWM wave at the stage's phase.
"""

from typing import NamedTuple

from numba import types
from numba.extending import overload

from ..control.controller import integrating_flag, phase_commands
from ..control.pid import FULL_DUTY, on_time, pid_output
from ..control.strategies import Strategy
from ..jit import njit
from ..model.heat import wire_temperature_rate
from ..model.hysteresis import AUTHORS_CALLS
from ..model.hysteresis_authors import call_record, committed_call
from ..model.records import Controller, WireInput
from .clock import TICKS_PER_S
from .pwm import sampled_drive
from .tuples import set_item, with_field


class Stages(NamedTuple):
    """What the later stages of the authors' solver need besides the state."""

    run: object  #: the kernel's run record
    cmds: tuple  #: the control tick's commands, one per wire
    enabled: int  #: the segment's enabled wires
    q_target: float  #: the segment's target [rad or m]
    low: float  #: the PWM's low level (V_L, or 0 A with a current drive)
    phase_mid: float  #: where in its period the PWM is read at h/2 [s]
    phase_end: float  #: where in its period the PWM is read at h [s]
    error_major: float  #: the Derivative block's input at the step's major time, q_F - q [rad or m]


class DerivativeMemory(NamedTuple):
    """What a Simulink Derivative block keeps: its input at the last major step."""

    error: float  #: the input (q_F - q) [rad or m]
    tick: int  #: when (-1: no major step yet)


#: before the first major step
NO_MAJOR_STEP = DerivativeMemory(0.0, -1)


@njit(cache=True, forceinline=True)
def derivative_block(error, error_last, dt):
    """A Simulink ``Derivative`` block's output: (u - u_last) / (t - t_last).

    ``error_last`` is the input at the last major step, ``dt`` [s] the time since it; 0 when
    there is none (``dt <= 0``; the block's initial output is 0). As Simulink implements the
    block: two (time, input) pairs written at major steps only (``TimeStampA/B``,
    ``LastUAtTimeA/B``), the output taken against the latest one before the current time,
    whether that is a major or a minor (stage) time.
    """
    if dt <= 0.0:
        return 0.0
    return (error - error_last) / dt


def pid_at_rate(ctrl, model, enabled, q_target, y, cmds, integrating, error_rate):
    """(commands, integrating): the paper's PID (Eq. 12a) at state ``y`` with the error rate
    ``error_rate`` (their Derivative block's) in place of -q'; any other controller keeps
    ``cmds`` (the authors' solver emulates their PID only). Dispatched on the controller
    record's type (:data:`_RATE_LAWS`)."""
    impl = _RATE_LAWS.get(type(ctrl), _keep_commands)
    return impl(ctrl, model, enabled, q_target, y, cmds, integrating, error_rate)


@njit(cache=True, forceinline=True)
def _pid_rate(ctrl, model, enabled, q_target, y, cmds, integrating, error_rate):
    e = q_target - y.q
    u = pid_output(e, error_rate, y.error_integral, ctrl.K_P, ctrl.K_V, ctrl.K_I)
    return (phase_commands(model, enabled, u, q_target, y.q, model.drive.V_H_V),
            integrating_flag(model, u, e, FULL_DUTY))


@njit(cache=True, forceinline=True)
def _keep_commands(ctrl, model, enabled, q_target, y, cmds, integrating, error_rate):
    return cmds, integrating


#: the controller records the authors' solver emulates, and their law at a given error rate
_RATE_LAWS = {Controller: _pid_rate}


@overload(pid_at_rate)
def _pid_at_rate(ctrl, model, enabled, q_target, y, cmds, integrating, error_rate):
    if not isinstance(ctrl, types.BaseNamedTuple):
        return None
    law = _RATE_LAWS.get(ctrl.instance_class, _keep_commands)
    return lambda ctrl, model, enabled, q_target, y, cmds, integrating, error_rate: law(
        ctrl, model, enabled, q_target, y, cmds, integrating, error_rate)


@njit(cache=True, forceinline=True)
def major_commands(model, run, t, s, y, cmds, integrating, memory):
    """(commands, integrating) at a control tick ``t`` (a major step): the PID's with the error
    rate of the Derivative block (:func:`derivative_block`) against the previous major step
    ``memory``, in place of the tick's ``cmds`` (closed loop only)."""
    if run.strategy == Strategy.OPEN_LOOP:
        return cmds, integrating
    dt = (t - memory.tick) * run.tick_s if memory.tick >= 0 else 0.0
    rate = derivative_block(s.q_target - y.q, memory.error, dt)
    return pid_at_rate(model.controller, model, s.enabled, s.q_target, y, cmds, integrating, rate)


@njit(cache=True, forceinline=True)
def stage_inputs(model, inputs, y, st, phase, since):
    """``inputs`` with each wire's drive and heating phase at stage state ``y``, ``since`` s
    after the major step, ``phase`` s into the PWM period.

    Closed loop with a controller evaluated continuously (``run.update_ticks == 0``): the
    commands from the PID (Eq. 12a) at ``y`` with the Derivative block's error rate against
    the major step; otherwise the tick's ``cmds``.
    """
    run = st.run
    cmds = st.cmds
    if run.strategy != Strategy.OPEN_LOOP and run.update_ticks == 0:
        rate = derivative_block(st.q_target - y.q, st.error_major, since)
        cmds = pid_at_rate(model.controller, model, st.enabled, st.q_target, y, cmds, 1.0, rate)[0]
    period = run.pwm_ticks / TICKS_PER_S
    wis = inputs.wires
    for i in range(len(wis)):
        c = cmds[i]
        d = sampled_drive(c.level, st.low, c.duty, on_time(c.duty, period), phase)
        wis = set_item(wis, i, WireInput(d, c.heating, wis[i].branch, wis[i].depth))
    return with_field(inputs, "wires", wis)


@njit(cache=True, forceinline=True)
def call_branches(model, y, inputs):
    """``inputs`` with each wire's branch for an evaluation at state ``y``: the authors' call
    (rule ``AUTHORS_CALLS``) takes the sign of its own dT/dt (Eq. 11 at the evaluation's drive
    and phase; their model has no latent heat); any other rule keeps its branch."""
    wis = inputs.wires
    for i in range(len(wis)):
        wi = wis[i]
        if wi.branch.rule != AUTHORS_CALLS:
            continue
        wire, ws = model.wires[i], y.wires[i]
        dT = wire_temperature_rate(wire, ws.T_C, ws.T_case_C, wi.drive, wi.heating, inputs.current_drive,
                                   model.options)
        wis = set_item(wis, i, WireInput(wi.drive, wi.heating, call_record(wi.branch, dT), wi.depth))
    return with_field(inputs, "wires", wis)


@njit(cache=True, forceinline=True)
def commit_calls(model, y, inputs, aux):
    """``inputs`` with the authors' globals after the evaluation at ``y`` that gave ``aux``
    (each wire's xi and stress there; rule ``AUTHORS_CALLS`` only)."""
    wis = inputs.wires
    for i in range(len(wis)):
        wi = wis[i]
        if wi.branch.rule != AUTHORS_CALLS:
            continue
        a = aux.wires[i]
        rec = committed_call(wi.branch, y.wires[i].T_C, a.sigma_Pa, a.xi, model.wires[i])
        wis = set_item(wis, i, WireInput(wi.drive, wi.heating, rec, wi.depth))
    return with_field(inputs, "wires", wis)
