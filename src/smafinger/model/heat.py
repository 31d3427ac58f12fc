"""Eq. (11): Joule heating with natural convection.

    M_w C_p dT/dt = P' - h A_w (T - T_amb),    h = h0 + h2 T^2

per unit length of wire: M_w = rho_w S_w [kg/m], A_w = pi d_w [m^2/m], P' the electrical power
per metre [W/m]. How the drive gives P' is a model option (MODEL-NOTES):

- ``per-metre`` (the paper's sets): Eq. (11) read literally, P' = V^2 / R_w with R_w in Ohm/m.
  This is the reading of the authors' model and the one that gives the paper's heating rate
  (about 30 degC/s at 8 V); it is V^2 / R_w whatever the wire's length.
- ``whole-wire`` (physical): the voltage V across the whole wire of resistance R_w L_w delivers
  V^2 / (R_w L_w), spread over its length: P' = V^2 / (R_w L_w^2).

A current drive I gives P' = I^2 R_w in either reading. The heat-transfer coefficients are the
heating ones while the wire's controller is in its heating phase and the cooling ones otherwise
(Sec. 3.2, MODEL-NOTES).
"""

from numba import njit

from ..parameters.options import JouleHeating


@njit(cache=True, inline="always")
def convection_coefficient(T, h0, h2):
    """h = h0 + h2 T^2 [W/(m^2 K)] (Eq. 11), T in degC as in the paper."""
    return h0 + h2 * T * T


@njit(cache=True, inline="always")
def joule_power_per_m(wire, drive, current_drive, reading):
    """P' [W/m]: electrical power per metre of wire for a voltage (or current) ``drive``."""
    if current_drive:
        return drive * drive * wire.resistance_ohm_per_m
    if reading == JouleHeating.PER_METRE:
        return drive * drive / wire.resistance_ohm_per_m
    return drive * drive / (wire.resistance_ohm_per_m * wire.wire_length_m * wire.wire_length_m)


@njit(cache=True, inline="always")
def electrical_power(wire, drive, current_drive):
    """Power at the wire's terminals [W]: V^2 / (R_w L_w) or I^2 R_w L_w."""
    if current_drive:
        return drive * drive * wire.resistance_ohm
    return drive * drive / wire.resistance_ohm


@njit(cache=True, inline="always")
def heat_balance(T, P, h, T_amb, M_w, C_p, A_w):
    """dT/dt [degC/s] of Eq. (11) for power P' [W/m] and coefficient h."""
    return (P - h * A_w * (T - T_amb)) / (M_w * C_p)


@njit(cache=True, inline="always")
def wire_temperature_rate(wire, T, drive, heating, current_drive, reading):
    """Eq. (11) for a wire, with the heating or cooling coefficients of its phase."""
    if heating:
        h = convection_coefficient(T, wire.h0_heating_W_m2K, wire.h2_heating_W_m2K3)
    else:
        h = convection_coefficient(T, wire.h0_cooling_W_m2K, wire.h2_cooling_W_m2K3)
    P = joule_power_per_m(wire, drive, current_drive, reading)
    return heat_balance(T, P, h, wire.T_amb_C, wire.mass_per_length_kg_m, wire.specific_heat_J_kgK,
                        wire.perimeter_m)


def steady_state_temperature(P, h, T_amb, A_w):
    """Closed form of Eq. (11) at constant h: T_ss = T_amb + P' / (h A_w)."""
    return T_amb + P / (h * A_w)


def time_constant(h, M_w, C_p, A_w):
    """Closed form of Eq. (11) at constant h: tau = M_w C_p / (h A_w) [s]."""
    return M_w * C_p / (h * A_w)
