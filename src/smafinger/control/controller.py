"""The control tick: what each wire is commanded until the next tick (Eq. 12, Sec. 2.6).

Closed loop: one PID output u (Eq. 12a) on the error q_F - q, turned into a duty per enabled
wire by :func:`~smafinger.control.strategies.wire_command`. Open loop: a program gives each
wire its drive level and duty. Both return a tuple of
:class:`~smafinger.control.strategies.Command`, one per wire.
"""

from ..engine.tuples import filled, set_item
from ..jit import njit
from ..parameters.options import AntiWindup, DampingSwitch
from .pid import FULL_DUTY, pid_output, saturated_against
from .strategies import Command, is_enabled, wire_command


@njit(cache=True, forceinline=True)
def phase_commands(model, enabled, u, q_target, q, level):
    """One signed controller output u [%] as a command per wire: the phase selection of Sec. 2.6.

    A direction +1 wire gets clamp(u), a direction -1 wire clamp(-u), each only if enabled and
    in its heating phase (or kept on in cooling, ``controller_in_cooling``); ``q`` is the
    controller's idea of the coordinate (measured, or estimated by a self-sensing controller).
    """
    keep_on = model.options.controller_in_cooling
    w = model.wires
    cmds = filled(w, Command(False, False, 0.0, level))
    for i in range(len(w)):
        cmds = set_item(cmds, i, wire_command(u, is_enabled(enabled, i), w[i].direction, q_target, q,
                                              keep_on, level))
    return cmds


@njit(cache=True, forceinline=True)
def integrating_flag(model, u, e, limit):
    """1.0 while the error integral runs, 0.0 while anti-windup freezes it (Eq. 12a): the law's
    output ``u`` is at ``limit`` (DC%; the full duty, 100, for the PID) and the error pushes it further."""
    frozen = model.options.anti_windup == AntiWindup.CLAMP and saturated_against(u, e, limit)
    return 0.0 if frozen else 1.0


@njit(cache=True, forceinline=True)
def pid_commands(model, enabled, q_target, state, level):
    """(commands, integrating): the PID (Eq. 12a) and the phase selection of Sec. 2.6.

    ``integrating`` is 0.0 while anti-windup freezes the error integral.
    """
    c = model.controller
    e = q_target - state.q
    u = pid_output(e, -state.v, state.error_integral, c.K_P, c.K_V, c.K_I)
    return phase_commands(model, enabled, u, q_target, state.q, level), integrating_flag(model, u, e, FULL_DUTY)


@njit(cache=True, forceinline=True)
def pid_tick(ctrl, cstate, model, s, y, inputs, geom, geom_q, t_s, started):
    """The paper's PWM-PID as a controller (:mod:`.interface`): no state of its own, every sensor
    exact (it reads the plant state: q, q' and the error integral)."""
    cmds, integrating = pid_commands(model, s.enabled, s.q_target, y, model.drive.V_H_V)
    return cmds, integrating, cstate


@njit(cache=True)
def pid_initial(ctrl, model):
    return ()


@njit(cache=True, forceinline=True)
def program_commands(cmds, levels, duties):
    """Open loop: each wire at its program's level and duty (enabled while both are positive)."""
    for i in range(len(cmds)):
        on = levels[i] > 0.0 and duties[i] > 0.0
        cmds = set_item(cmds, i, Command(on, on, duties[i] if on else 0.0, levels[i]))
    return cmds


@njit(cache=True, forceinline=True)
def viscous_coefficient(dynamics, cmds, rule):
    """C_DF: the heating value while any wire heats (or is enabled, per ``rule``; always with
    ``heating-value``), else the cooling value."""
    if rule == DampingSwitch.HEATING_VALUE:
        return dynamics.viscous_heating
    hot = False
    for i in range(len(cmds)):
        if (cmds[i].enabled if rule == DampingSwitch.ENABLED else cmds[i].heating):
            hot = True
    return dynamics.viscous_heating if hot else dynamics.viscous_cooling
