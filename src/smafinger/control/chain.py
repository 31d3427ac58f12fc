"""The controllers beyond the paper's, as one chain: estimate -> law -> phase selection -> shaping.

At every tick (:mod:`.interface`):

1. **estimate** q and q' (:class:`Estimator`): the position sensor, or the wires' resistance
   alone (:mod:`.selfsensing`, Eqs. S1-S2);
2. **law** (:class:`Law`): one signed output DC% from the error e = q_F - q_hat, its rate -q'_hat
   and its integral: the PID of Eq. (12a), the fuzzy-scheduled PID (:mod:`.fuzzy`) or sliding
   mode (:mod:`.sliding`);
3. **phase selection** of Sec. 2.6 (:func:`~.controller.phase_commands`): a duty per wire,
   honouring the strategy's enable mask and the interlock;
4. **shaping** (:mod:`.rapid`): rapid heating, a temperature limit, pre-heating (identity with
   :data:`NO_SHAPING`).

Every built-in controller of :mod:`.params` except the paper's own PID record is a
:class:`ControlChain` with its parts set: one record type, so the compiled loop is built once
per mechanism for all of them (each record type costs a full compile of the loop, one to two
minutes). With a position sensor the integral is the plant state's (Eq. 12a, as the paper's
PID); with the resistance estimate it is the chain's own. A chain with the PID law, the position
sensor and no shaping computes exactly what the paper's PID does (a test checks the bits).
"""

import math
from enum import IntEnum
from typing import NamedTuple

from ..jit import njit
from ..parameters.options import IntegralReset
from .controller import integrating_flag, phase_commands
from .fuzzy import FuzzyPID, fuzzy_output
from .pid import FULL_DUTY, pid_output
from .rapid import RapidHeating, shape_commands
from .selfsensing import ResistanceMap, estimate, filtered_rate
from .sensing import Sensors, measure
from .sliding import SlidingMode, sliding_output


class Estimator(IntEnum):
    SENSOR = 0  #: q and q' from the position sensor
    RESISTANCE = 1  #: q_hat from the resistances (Eq. S1), q'_hat filtered (Eq. S2)


class Law(IntEnum):
    PID = 0  #: Eq. (12a)
    FUZZY_PID = 1  #: Eq. (12a) with fuzzy-scheduled gains
    SLIDING_MODE = 2  #: Eqs. (SM1)-(SM2)


class PIDGains(NamedTuple):
    K_P: float
    K_V: float
    K_I: float


class ControlChain(NamedTuple):
    sensors: Sensors
    estimator: Estimator
    rmap: ResistanceMap  #: used by Estimator.RESISTANCE
    law: Law
    pid: PIDGains  #: used by Law.PID
    fuzzy: FuzzyPID  #: used by Law.FUZZY_PID
    sliding: SlidingMode  #: used by Law.SLIDING_MODE
    shaping: RapidHeating


class ChainState(NamedTuple):
    q_hat: float  #: the last estimate (resistance estimator)
    v_hat: float
    integral: float  #: the chain's own error integral (resistance estimator) [q s]
    t_s: float  #: time of the last tick
    primed: bool  #: a previous tick exists


#: shaping that changes nothing
NO_SHAPING = RapidHeating(0.0, -math.inf, math.inf, -math.inf, 0.0)


@njit(cache=True)
def chain_initial(ctrl, model):
    return ChainState(0.0, 0.0, 0.0, 0.0, False)


@njit(cache=True, forceinline=True)
def law_output(ctrl, e, de, integral):
    """The law's signed DC%."""
    if ctrl.law == Law.FUZZY_PID:
        return fuzzy_output(ctrl.fuzzy, e, de, integral)
    if ctrl.law == Law.SLIDING_MODE:
        return sliding_output(ctrl.sliding, e, de, integral)
    g = ctrl.pid
    return pid_output(e, de, integral, g.K_P, g.K_V, g.K_I)


@njit(cache=True, forceinline=True)
def law_limit(ctrl):
    """The DC% at which the law's output stops growing (anti-windup's saturation): the switching
    gain K of the sliding mode (Eq. SM2; the full duty if K is above it), else the full duty."""
    if ctrl.law == Law.SLIDING_MODE:
        return min(ctrl.sliding.K, FULL_DUTY)
    return FULL_DUTY


@njit(cache=True, forceinline=True)
def chain_tick(ctrl, cstate, model, s, y, inputs, geom, geom_q, t_s, started):
    """One tick of the chain (see the module docstring): (commands, integrating, state)."""
    m = measure(ctrl.sensors, model, s, y, inputs, geom, geom_q, t_s, started)
    dt = t_s - cstate.t_s if cstate.primed else 0.0
    if ctrl.estimator == Estimator.RESISTANCE:
        q = estimate(ctrl.rmap, m.R_ohm)
        v = filtered_rate(ctrl.rmap, cstate.v_hat, q, cstate.q_hat, dt)
        integral = 0.0 if started and model.options.integral_reset == IntegralReset.SEGMENT else cstate.integral
    else:
        q, v, integral = m.q, m.v, m.error_integral
    e = m.q_target - q
    u = law_output(ctrl, e, -v, integral)
    integrating = integrating_flag(model, u, e, law_limit(ctrl))
    cmds = shape_commands(ctrl.shaping, model, phase_commands(model, m.enabled, u, m.q_target, q,
                                                              model.drive.V_H_V), m)
    if ctrl.estimator == Estimator.RESISTANCE:
        # the chain integrates its own error (backward rectangle); the plant's integral is stopped
        return cmds, 0.0, ChainState(q, v, integral + integrating * e * dt, t_s, True)
    return cmds, integrating, ChainState(q, v, integral, t_s, True)
