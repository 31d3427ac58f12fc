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

from ..jit import njit
from ..parameters.options import JouleHeating, ThermalModel

#: Stefan-Boltzmann constant [W/(m^2 K^4)] (CODATA 2018, exact)
STEFAN_BOLTZMANN_W_m2K4 = 5.670374419e-8
#: 0 degC in kelvin
KELVIN = 273.15


@njit(cache=True, forceinline=True)
def convection_coefficient(T, h0, h2):
    """h = h0 + h2 T^2 [W/(m^2 K)] (Eq. 11), T in degC as in the paper."""
    return h0 + h2 * T * T


@njit(cache=True, forceinline=True)
def joule_power_per_m(wire, drive, current_drive, reading):
    """P' [W/m]: electrical power per metre of wire for a voltage (or current) ``drive``."""
    if current_drive:
        return drive * drive * wire.resistance_ohm_per_m
    if reading == JouleHeating.PER_METRE:
        return drive * drive / wire.resistance_ohm_per_m
    return drive * drive / (wire.resistance_ohm_per_m * wire.wire_length_m * wire.wire_length_m)


@njit(cache=True, forceinline=True)
def electrical_power(wire, drive, current_drive):
    """Power at the wire's terminals [W]: V^2 / (R_w L_w) or I^2 R_w L_w."""
    if current_drive:
        return drive * drive * wire.resistance_ohm
    return drive * drive / wire.resistance_ohm


@njit(cache=True, forceinline=True)
def heat_balance(T, P, h, T_amb, M_w, C_p, A_w):
    """dT/dt [degC/s] of Eq. (11) for power P' [W/m] and coefficient h."""
    return (P - h * A_w * (T - T_amb)) / (M_w * C_p)


@njit(cache=True, forceinline=True)
def wire_h(wire, T, heating):
    """h of Eq. (11) with the heating or cooling coefficients of the wire's phase (Sec. 3.2)."""
    if heating:
        return convection_coefficient(T, wire.h0_heating_W_m2K, wire.h2_heating_W_m2K3)
    return convection_coefficient(T, wire.h0_cooling_W_m2K, wire.h2_cooling_W_m2K3)


@njit(cache=True, forceinline=True)
def surroundings_C(wire, T_case, model):
    """The temperature the wire loses heat to: the ambient (Eq. 11) or the casing air (two-node)."""
    return T_case if model == ThermalModel.TWO_NODE else wire.T_amb_C


@njit(cache=True, forceinline=True)
def wire_temperature_rate(wire, T, T_case, drive, heating, current_drive, opts):
    """Eq. (11) for a wire, with the heating or cooling coefficients of its phase (no latent heat)."""
    h = wire_h(wire, T, heating)
    T_sur = surroundings_C(wire, T_case, opts.thermal_model)
    P = joule_power_per_m(wire, drive, current_drive, opts.joule_heating) - radiation_per_m(wire, T, T_sur)
    return heat_balance(T, P, h, T_sur, wire.mass_per_length_kg_m, wire.specific_heat_J_kgK, wire.perimeter_m)


@njit(cache=True, forceinline=True)
def radiation_per_m(wire, T, T_sur):
    """Radiative loss per metre [W/m] added to Eq. (11): eps sigma_SB A_w (T^4 - T_sur^4), kelvin inside.

    Stefan-Boltzmann law for a grey wire in large surroundings at ``T_sur`` [degC]. The paper
    lumps radiation into h (h2 T^2 stands for it); ``emissivity`` = 0 (every named set) leaves
    Eq. (11) as published.
    """
    eps = wire.emissivity
    if eps == 0.0:
        return 0.0
    Tk = T + KELVIN
    Sk = T_sur + KELVIN
    return eps * STEFAN_BOLTZMANN_W_m2K4 * wire.perimeter_m * (Tk ** 4 - Sk ** 4)


@njit(cache=True, forceinline=True)
def casing_temperature_rate(wire, T, T_case, heating, opts):
    """dT_case/dt of the two-node model:
    C_case dT_case/dt = h A_w (T - T_case) + eps sigma_SB A_w (T_K^4 - T_case,K^4) - G (T_case - T_amb).

    Per metre of wire: C_case = ``casing_heat_capacity_J_mK``, G = ``casing_loss_W_mK``; the wire
    side is what the wire loses in :func:`wire_temperature_rate`, Eq. (11)'s convection term and
    the radiation, both now to the casing (Sec. 3.2: "heat transfer between SMA wire and the
    inside air of the actuator, and ... the inside air and the open air"), so that every joule
    the wire gives off reaches the casing. 0 in the single-node model.
    """
    if opts.thermal_model != ThermalModel.TWO_NODE:
        return 0.0
    q_in = wire_h(wire, T, heating) * wire.perimeter_m * (T - T_case) + radiation_per_m(wire, T, T_case)
    q_out = wire.casing_loss_W_mK * (T_case - wire.T_amb_C)
    return (q_in - q_out) / wire.casing_heat_capacity_J_mK


@njit(cache=True, forceinline=True)
def latent_heat_rate(dT_no_latent, dsigma_free, dsigma_dT, xi_T, xi_s, wire):
    """dT/dt with the latent heat of the transformation (Eq. 11 plus M_w dH dxi/dt).

    Forming martensite (dxi/dt > 0) releases the latent heat dH per kilogram, reversing it absorbs
    it: M_w C_p dT/dt = (Eq. 11's right-hand side) + M_w dH (xi_T dT/dt + xi_s dsigma/dt), with
    dsigma/dt = ``dsigma_free`` - ``dsigma_dT`` dT/dt from the constitutive law; solved for dT/dt.
    ``latent_heat_J_kg`` = 0 (the paper's sets) returns ``dT_no_latent`` unchanged.
    """
    dH = wire.latent_heat_J_kg
    if dH == 0.0:
        return dT_no_latent
    r = dH / wire.specific_heat_J_kgK
    return (dT_no_latent + r * xi_s * dsigma_free) / (1.0 - r * xi_T + r * xi_s * dsigma_dT)


def steady_state_temperature(P, h, T_amb, A_w):
    """Closed form of Eq. (11) at constant h: T_ss = T_amb + P' / (h A_w)."""
    return T_amb + P / (h * A_w)


def time_constant(h, M_w, C_p, A_w):
    """Closed form of Eq. (11) at constant h: tau = M_w C_p / (h A_w) [s]."""
    return M_w * C_p / (h * A_w)
