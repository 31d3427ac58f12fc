"""Eq. (11) in plain Python: Joule heating, convection, the two-node casing and the latent heat.

Written from the paper (Gilardi et al., Robotica 28(5), 2010, Eq. 11 and Sec. 3.2) and
``shared/MODEL-NOTES.md``, not from ``smafinger.model``. SI units, temperatures in degC as in
the paper. Per metre of wire: M_w = rho_w S_w [kg/m], A_w = pi d_w [m^2/m].

- single node (Eq. 11): M_w C_p dT/dt = P' - h A_w (T - T_amb), h = h0 + h2 T^2;
- two nodes (Sec. 3.2, "between SMA wire and the inside air of the actuator, and ... the inside
  air and the open air"): the wire loses h A_w (T - T_case) to the casing air, which holds
  C_case [J/(m K)] and loses G (T_case - T_amb) [W/m] to the open air;
- latent heat dH [J/kg]: forming martensite releases it, M_w C_p dT/dt gains M_w dH dxi/dt.
"""

from __future__ import annotations


def convection(T: float, h0: float, h2: float) -> float:
    """h = h0 + h2 T^2 [W/(m^2 K)], T in degC (Eq. 11)."""
    return h0 + h2 * T**2


def joule_power_per_metre(drive: float, current: bool, whole_wire: bool, R_per_m: float, L_w: float) -> float:
    """Electrical power per metre of wire [W/m] (Eq. 11's V^2/R_w term).

    Voltage, ``per-metre`` reading (Eq. 11 literally): V^2 / R_w. Voltage, ``whole-wire``
    reading: the power V^2 / (R_w L_w) of the whole wire, divided by its length. Current I:
    I^2 R_w L_w over the whole wire, I^2 R_w per metre, in either reading.
    """
    if current:
        return drive**2 * R_per_m
    if whole_wire:
        return terminal_power(drive, False, R_per_m, L_w) / L_w
    return drive**2 / R_per_m


def terminal_power(drive: float, current: bool, R_per_m: float, L_w: float) -> float:
    """Power at the wire's terminals [W]: V^2 / (R_w L_w), or I^2 R_w L_w."""
    R = R_per_m * L_w
    return drive**2 * R if current else drive**2 / R


def temperature_rate(T: float, P_per_m: float, h: float, T_surround: float, M_w: float, C_p: float,
                     A_w: float) -> float:
    """dT/dt of Eq. (11) without latent heat: M_w C_p dT/dt = P' - h A_w (T - T_surround).

    ``T_surround`` is the ambient (single node) or the casing air (two nodes).
    """
    return (P_per_m - h * A_w * (T - T_surround)) / (M_w * C_p)


def casing_rate(T: float, T_case: float, h: float, A_w: float, G: float, C_case: float, T_amb: float) -> float:
    """dT_case/dt of the two-node model: C_case T_case' = h A_w (T - T_case) - G (T_case - T_amb)."""
    return (h * A_w * (T - T_case) - G * (T_case - T_amb)) / C_case


def with_latent_heat(dT_plain: float, dH_over_Cp: float, xi_T: float, xi_s: float, s_free: float,
                     s_T: float) -> float:
    """dT/dt with the latent heat, the stress rate being sigma' = s_free + s_T T'.

    C_p T' = C_p T'_plain + dH xi', xi' = xi_T T' + xi_s sigma' along the kinetics branch;
    with r = dH / C_p: T' (1 - r xi_T - r xi_s s_T) = T'_plain + r xi_s s_free.
    """
    r = dH_over_Cp
    return (dT_plain + r * xi_s * s_free) / (1.0 - r * xi_T - r * xi_s * s_T)
