"""Eqs. (1)-(2): the mechanism's dynamics with stick/slip friction, and its external load.

    I q'' = M_E - M_Fr                                                      (1a)
    M_E = sum over wires of -F dpath/dq  +  external load(q),   F = sigma S_w     (1b)
    M_Fr = sign(q')(M_DF + C_DF |q'|)   if |M_E| > M_SF                      (2)
    M_Fr = M_E                          if |M_E| <= M_SF (stuck)

For the joint, -F dpath/dq is F_U b_U for the upper tendon and -F_L b_L for the lower, and the
external load is gravity, -m g d_CM cos(theta) (Eq. 1b). For the linear actuator the wire's
term is its tension and the load is the bias spring and a constant force. Written in the
generalized coordinate q, Eqs. (1)-(2) hold for either: moments and radians for the joint,
forces and metres for the slider.

Sticking is a discrete state decided at step boundaries by the engine (:func:`stick_slip`):
the mechanism is held (q' = q'' = 0) while stuck and breaks away when |M_E| > M_SF. End stops
hold a slider the same way (:func:`end_stop`).
"""

from typing import NamedTuple

from numba import types
from numba.extending import overload

from ..jit import njit


class JointLoad(NamedTuple):
    """Gravity on the phalanx (Eq. 1b)."""

    gravity_moment_Nm: float  #: m g d_CM


class SliderLoad(NamedTuple):
    """The bias spring and a constant load on the slider."""

    bias_spring_K_N_m: float
    bias_spring_preload_N: float
    external_force_N: float


@njit(cache=True, forceinline=True)
def gravity_moment(load, cos_theta):
    """-m g d_CM cos(theta): gravity's moment about the joint [N m] (Eq. 1b)."""
    return -(load.gravity_moment_Nm * cos_theta)


@njit(cache=True, forceinline=True)
def bias_force(load, x):
    """Force of the bias spring and the constant load on the slider at x [N] (negative: against the wire)."""
    return -(load.bias_spring_preload_N + load.bias_spring_K_N_m * x + load.external_force_N)


def external_load(load, q, cos_q):
    """The mechanism's load at q, apart from the wires; dispatched on the load's type."""
    return _LOADS[type(load)](load, q, cos_q)


def _joint_load(load, q, cos_q):
    return gravity_moment(load, cos_q)


def _slider_load(load, q, cos_q):
    return bias_force(load, q)


#: each load record and its load function, called as f(load, q, cos_q)
_LOADS = {JointLoad: njit(cache=True, forceinline=True)(_joint_load),
          SliderLoad: njit(cache=True, forceinline=True)(_slider_load)}


@overload(external_load)
def _external_load(load, q, cos_q):
    if isinstance(load, types.BaseNamedTuple) and load.instance_class in _LOADS:
        f = _LOADS[load.instance_class]
        return lambda load, q, cos_q: f(load, q, cos_q)
    return None


@njit(cache=True)
def mechanism_load(load, q, cos_q):
    """:func:`external_load`, also callable from Python."""
    return external_load(load, q, cos_q)


@njit(cache=True, forceinline=True)
def wire_load(sigma, area, dpath_dq):
    """A wire's generalized force -F dpath/dq with F = sigma S_w (Eq. 1b)."""
    return sigma * area * (-dpath_dq)


@njit(cache=True, forceinline=True)
def sliding_friction(omega, M_DF, C_DF):
    """M_Fr [N m] of Eq. (2) while sliding."""
    if omega > 0.0:
        return M_DF + C_DF * omega
    if omega < 0.0:
        return -(M_DF - C_DF * omega)
    return 0.0


@njit(cache=True, forceinline=True)
def angular_acceleration(M_E, omega, stuck, I, M_DF, C_DF):
    """q'' of Eq. (1a) (theta'' [rad/s^2] for the joint)."""
    if stuck:
        return 0.0
    return (M_E - sliding_friction(omega, M_DF, C_DF)) / I


@njit(cache=True, forceinline=True)
def stick_slip(stuck, first, load, v, v_prev, dyn, restick):
    """Eq. (2) as a discrete decision at a sub-step start: is the mechanism held?

    At the start it is held if at rest with |M_E| <= M_SF. A held mechanism breaks away when
    |M_E| > M_SF. A moving one sticks again (``restick``) when |M_E| <= M_SF and it is slow
    (|q'| <= stick velocity) or reversing.
    """
    me = abs(load)
    if first:
        return me <= dyn.static_friction and v == 0.0
    if stuck:
        return not me > dyn.static_friction
    if restick and me <= dyn.static_friction and (abs(v) <= dyn.stick_velocity or v * v_prev < 0.0):
        return True
    return False


@njit(cache=True, forceinline=True)
def end_stop(q, v, dyn):
    """(q, v) after a step, clamped to the end stops [q_min, q_max] (a stop absorbs the motion)."""
    if q > dyn.q_max:
        return dyn.q_max, min(v, 0.0)
    if q < dyn.q_min:
        return dyn.q_min, max(v, 0.0)
    return q, v


@njit(cache=True, forceinline=True)
def at_stop_holding(q, load, dyn):
    """True while the mechanism rests on a stop and its load pushes it into the stop."""
    return (q >= dyn.q_max and load > 0.0) or (q <= dyn.q_min and load < 0.0)
