"""Self-sensing control: the loop closed on the wires' resistance alone (no angle or position sensor).

The coordinate is estimated from the resistances (:mod:`smafinger.model.resistance`) through a
calibration map fitted once against a position sensor (:mod:`.calibration`), as in the
self-sensing SMA literature (Ikuta, Tsukamoto and Hirose, "Shape memory alloy servo actuator
system with electric resistance feedback and application for active endoscope", IEEE ICRA
1988; Ma, Song and Lee, "Position control of shape memory alloy actuators with internal
electrical resistance feedback using neural networks", Smart Mater. Struct. 13:777-783, 2004)::

    q_hat = c0 + sum_i (c1_i r_i + c2_i r_i^2 + c3_i r_i^3),   r_i = R_i / R_ref,i - 1     (S1)

Its rate is the difference of successive estimates through a first-order filter of time
constant ``rate_tau_s``::

    v_hat += (dq_hat / dt - v_hat) dt / (tau + dt)                                       (S2)

and the control law (:mod:`.chain`) runs on q_F - q_hat with its own error integral (each
tick's error times the interval before it, added after the tick; restarted like the paper's,
``integral_reset``, and frozen by ``anti_windup``). The phase selection (Sec. 2.6) uses q_hat
too: the controller never sees q.
"""

from typing import NamedTuple

from ..jit import njit


class ResistanceMap(NamedTuple):
    """The calibration of Eq. (S1) (per-wire tuples) and the rate filter of Eq. (S2)."""

    R_ref: tuple  #: per wire [ohm]
    c0: float
    c1: tuple
    c2: tuple
    c3: tuple
    rate_tau_s: float


@njit(cache=True, forceinline=True)
def estimate(rmap, R):
    """q_hat of Eq. (S1) from the resistances R (a per-wire tuple)."""
    q = rmap.c0
    for i in range(len(R)):
        r = R[i] / rmap.R_ref[i] - 1.0
        q += r * (rmap.c1[i] + r * (rmap.c2[i] + r * rmap.c3[i]))
    return q


@njit(cache=True, forceinline=True)
def filtered_rate(rmap, v_prev, q_hat, q_prev, dt):
    """v_hat of Eq. (S2) (0 on the first tick: ``dt <= 0``)."""
    if dt <= 0.0:
        return 0.0
    return v_prev + ((q_hat - q_prev) / dt - v_prev) * dt / (rmap.rate_tau_s + dt)
