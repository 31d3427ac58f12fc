"""The authors' Simulink solver (``authors-ode4``): what each stage of their ode4 sees.

In the authors' model (MODEL-NOTES, "Details of the authors' 2020 model") the control block is
evaluated at every solver evaluation: at each of ode4's four stages the PID (Eq. 12a) is
computed from that stage's state, the phase chosen (Sec. 2.6) and the PWM wave read at the
stage's time (:func:`.pwm.sampled_phases`). :func:`stage_inputs` builds those held inputs.
Their controller's sampling times are 0 (``dtCtrl_H = dtCtrl_C = 0``, ``Initialization.m``), so
it is re-evaluated at every call; a run with a controller period, or an open-loop program, keeps
the commands of its tick and only reads the PWM wave at the stage's phase.
"""

from typing import NamedTuple

from numba import njit, types
from numba.extending import overload

from ..control.controller import pid_commands
from ..control.pid import on_time
from ..control.strategies import Strategy
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


def stage_commands(ctrl, model, enabled, q_target, y, cmds):
    """The commands at a later stage: the paper's PID (Eq. 12a) re-evaluated at the stage's state
    ``y``; any other controller keeps its tick's ``cmds`` (the authors' solver emulates their
    PID only). Compiled code only: dispatched on the controller record's type."""
    raise NotImplementedError("stage_commands() is compiled code: call it from a numba function")


@overload(stage_commands)
def _stage_commands(ctrl, model, enabled, q_target, y, cmds):
    if isinstance(ctrl, types.BaseNamedTuple) and ctrl.instance_class is Controller:
        def impl(ctrl, model, enabled, q_target, y, cmds):
            return pid_commands(model, enabled, q_target, y, model.drive.V_H_V)[0]
    else:
        def impl(ctrl, model, enabled, q_target, y, cmds):
            return cmds
    return impl


@njit(cache=True, inline="always")
def stage_inputs(model, inputs, y, st, phase):
    """``inputs`` with each wire's drive and heating phase at stage state ``y``, ``phase`` s into the period.

    Closed loop with a controller evaluated continuously (``run.update_ticks == 0``): the
    commands from the PID (Eq. 12a) at ``y`` (the drive and the heating phase); otherwise the
    tick's ``cmds``.
    """
    run = st.run
    cmds = st.cmds
    if run.strategy != Strategy.OPEN_LOOP and run.update_ticks == 0:
        cmds = stage_commands(model.controller, model, st.enabled, st.q_target, y, cmds)
    period = run.pwm_ticks / TICKS_PER_S
    wis = inputs.wires
    for i in range(len(wis)):
        c = cmds[i]
        d = sampled_drive(c.level, st.low, c.duty, on_time(c.duty, period), phase)
        wis = set_item(wis, i, WireInput(d, c.heating, wis[i].branch, wis[i].depth))
    return with_field(inputs, "wires", wis)
