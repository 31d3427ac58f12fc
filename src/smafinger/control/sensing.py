"""What a controller measures at its tick: the declared sensors, and each wire's resistance.

A controller declares its :class:`Sensors`. The drive electronics always know each wire's
resistance (the voltage across it over the current through it), so every controller receives
it (:mod:`smafinger.model.resistance`, phase and temperature dependent). That includes the ticks
at which a wire is off (0 % duty, or V_L = 0 between pulses): the bench assumes a board that
passes a small sensing current through every wire, as self-sensing boards do, and neglects that
current's heating (10 mA in the paper's 3.3 ohm wire: 0.3 mW, against 19 W at 8 V). The
coordinate and its rate (an angle encoder or a position sensor) and the wire temperatures (a
thermocouple or similar on each wire) are NaN unless declared: a controller that closes the
loop on resistance alone cannot read the angle by mistake, and the NaN duty that follows stops
the run at that tick (:class:`~smafinger.engine.run.DutyNotANumber`).

Measurements are exact (no noise or quantisation): the bench compares control laws, not
sensors.
"""

import math
from typing import NamedTuple

from ..engine.rhs import geometry_at
from ..engine.tuples import filled, set_item
from ..jit import njit
from ..model.resistance import resistance_at


class Sensors(NamedTuple):
    """The sensors a controller declares."""

    position: bool  #: the coordinate (joint angle or slider position) and its rate
    temperature: bool  #: a temperature sensor on every wire


class Measurement(NamedTuple):
    """What a controller sees at a tick (SI units; q in rad for the joint, m for a slider)."""

    t_s: float
    q_target: float  #: the reference (theta_F of Eq. 12a)
    enabled: int  #: the strategy's enable mask (bit i: wire i)
    started: bool  #: a new profile segment started at this tick
    q: float  #: NaN without a position sensor
    v: float  #: its rate; NaN without a position sensor
    error_integral: float  #: the integral of q_target - q the plant state carries (Eq. 12a); NaN without
    T_C: tuple  #: per wire; NaN without temperature sensors
    R_ohm: tuple  #: per wire: its resistance


@njit(cache=True)
def measure(sensors, model, s, y, inputs, geom, geom_q, t_s, started):
    """The :class:`Measurement` at state ``y`` (``geom`` is the geometry at ``geom_q``)."""
    g = geometry_at(y.q, geom_q, geom, model)
    w = model.wires
    T = filled(w, math.nan)
    R = filled(w, 0.0)
    for i in range(len(w)):
        ws = y.wires[i]
        R = set_item(R, i, resistance_at(w[i], ws, inputs.wires[i].branch, g.routes[i][0],
                                         model.options.stress_law))
        if sensors.temperature:
            T = set_item(T, i, ws.T_C)
    if sensors.position:
        return Measurement(t_s, s.q_target, s.enabled, started, y.q, y.v, y.error_integral, T, R)
    return Measurement(t_s, s.q_target, s.enabled, started, math.nan, math.nan, math.nan, T, R)
