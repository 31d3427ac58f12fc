"""Eq. (11): Joule heating with natural convection.

    M_w C_p dT/dt = V^2 / R_w - h A_w (T - T_amb),    h = h0 + h2 T^2

Per unit length of wire, read literally (MODEL-NOTES): M_w = rho_w S_w [kg/m],
A_w = pi d_w [m^2/m], R_w [Ohm/m]. This is the reading used by the authors' model and the
one that gives the paper's heating rate (about 30 degC/s at 8 V).
"""

from numba import njit


@njit(cache=True)
def convection_coefficient(T, h0, h2):
    """h = h0 + h2 T^2 [W/(m^2 K)] (Eq. 11), T in degC as in the paper."""
    return h0 + h2 * T * T


@njit(cache=True)
def temperature_rate(T, V, h0, h2, T_amb, R_w, M_w, C_p, A_w):
    """dT/dt [degC/s] of Eq. (11)."""
    h = h0 + h2 * T * T
    return (V * V / R_w - h * A_w * (T - T_amb)) / (M_w * C_p)


def steady_state_temperature(V, h, T_amb, R_w, A_w):
    """Closed form of Eq. (11) at constant h: T_ss = T_amb + V^2 / (R_w h A_w)."""
    return T_amb + V * V / (R_w * h * A_w)


def time_constant(h, M_w, C_p, A_w):
    """Closed form of Eq. (11) at constant h: tau = M_w C_p / (h A_w) [s]."""
    return M_w * C_p / (h * A_w)
