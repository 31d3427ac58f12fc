"""Packing a :class:`ParameterSet` into the flat float array the compiled kernels read.

This is the API edge: degrees become radians here, derived quantities (cross-section, mass
per length, B's radius and angles, initial spring elongations, initial stresses and total
strains) are computed here from the set, never stored in it.
"""

from __future__ import annotations

import math

import numpy as np

from ..parameters.base import ParameterError, ParameterSet
from .constitutive import youngs_modulus
from .kinematics import both_tendons

_NAMES = """
S_w L_w M_w C_p R_w A_w A_S0 A_F0 c_A M_S0 M_F0 c_M D_A D_M eps_R T_amb T_init xi_init
h0_h h2_h h0_c h2_c I m g d_CM M_SF M_DF C_DF_h C_DF_c omega_stick theta0
r a0_u a0_l a1 a2 a4 a5 K_S xlim_u xlim_l fact V_H V_L t_P K_P K_V K_I
keep_on_cooling integral_never anti_windup stress_algebraic stick_initial_only damping_enabled
reversal path0_u path0_l sigma0_u sigma0_l eps_tot0_u eps_tot0_l x0_u x0_l
""".split()

#: index of each packed value, e.g. ``IDX["S_w"]``
IDX = {n: i for i, n in enumerate(_NAMES)}
N_PARAMS = len(_NAMES)
globals().update({f"P_{n}": i for n, i in IDX.items()})


def geometry(p: ParameterSet) -> tuple[float, float, float]:
    """(r, alpha0_upper, alpha0_lower) of Eq. (3) from the MODEL-NOTES dimensions."""
    r = math.hypot(p.a1_m, p.a3_m)
    return r, math.atan2(p.a1_m, p.a3_m), math.atan2(-p.a1_m, p.a3_m)


def initial_spring_elongations(p: ParameterSet) -> tuple[float, float]:
    """Initial spring elongations (upper, lower) [m].

    ``spring_init = "given"``: from the two initial spring lengths. ``"equilibrium"``: the
    lower as given, the upper from the friction-free moment balance at theta0 (Eq. 1b with
    M_E = 0), as in the authors' model.
    """
    x_l = p.spring_length_lower_m - p.spring_free_length_m
    if p.spring_init == "given":
        return p.spring_length_upper_m - p.spring_free_length_m, x_l
    r, a0u, a0l = geometry(p)
    th0 = math.radians(p.theta0_deg)
    _, _, b_u, _, _, b_l = both_tendons(th0, r, a0u, a0l, p.a1_m, p.a2_m, p.a4_m, p.a5_m)
    F_l = p.spring_K_N_m * x_l
    F_u = (F_l * b_l + p.mass_kg * p.gravity_m_s2 * p.d_CM_m * math.cos(th0)) / b_u
    if F_u <= 0.0:
        raise ParameterError(
            f"spring_init = 'equilibrium' needs a pulling upper tendon at theta0_deg = "
            f"{p.theta0_deg}; the moment balance gives F_upper = {F_u:.4g} N"
        )
    return F_u / p.spring_K_N_m, x_l


def pack(p: ParameterSet) -> np.ndarray:
    """The flat float64 parameter array of the kernels."""
    v = np.zeros(N_PARAMS)

    def put(name: str, value: float) -> None:
        v[IDX[name]] = value

    S_w = math.pi * p.wire_diameter_m**2 / 4.0
    put("S_w", S_w)
    put("L_w", p.wire_length_m)
    put("M_w", p.wire_density_kg_m3 * S_w)
    put("C_p", p.specific_heat_J_kgK)
    put("R_w", p.resistance_ohm_per_m)
    put("A_w", math.pi * p.wire_diameter_m)
    for n in ("A_S0", "A_F0", "M_S0", "M_F0"):
        put(n, getattr(p, f"{n}_C"))
    put("c_A", p.c_A_Pa_per_C)
    put("c_M", p.c_M_Pa_per_C)
    put("D_A", p.D_A_Pa)
    put("D_M", p.D_M_Pa)
    put("eps_R", p.eps_R)
    put("T_amb", p.T_amb_C)
    put("T_init", p.T_init_C)
    put("xi_init", p.xi_init)
    put("reversal", p.minor_loop_reversal_C)
    put("h0_h", p.h0_heating_W_m2K)
    put("h2_h", p.h2_heating_W_m2K3)
    put("h0_c", p.h0_cooling_W_m2K)
    put("h2_c", p.h2_cooling_W_m2K3)
    put("I", p.inertia_kg_m2)
    put("m", p.mass_kg)
    put("g", p.gravity_m_s2)
    put("d_CM", p.d_CM_m)
    put("M_SF", p.M_SF_Nm)
    put("M_DF", p.M_DF_Nm)
    put("C_DF_h", p.C_DF_heating_Nms)
    put("C_DF_c", p.C_DF_cooling_Nms)
    put("omega_stick", p.stick_velocity_rad_s)
    th0 = math.radians(p.theta0_deg)
    put("theta0", th0)
    r, a0u, a0l = geometry(p)
    put("r", r)
    put("a0_u", a0u)
    put("a0_l", a0l)
    for n in ("a1", "a2", "a4", "a5"):
        put(n, getattr(p, f"{n}_m"))
    put("K_S", p.spring_K_N_m)
    x0_u, x0_l = initial_spring_elongations(p)
    put("x0_u", x0_u)
    put("x0_l", x0_l)
    put("xlim_u", x0_u + p.slack_m - p.slack_band_m)
    put("xlim_l", x0_l + p.slack_m - p.slack_band_m)
    put("fact", p.slack_penalty_per_mm)
    put("V_H", p.V_H_V)
    put("V_L", p.V_L_V)
    put("t_P", p.pwm_period_s)
    put("K_P", p.K_P_per_rad)
    put("K_V", p.K_V_s_per_rad)
    put("K_I", p.K_I_per_rad_s)
    put("keep_on_cooling", float(p.controller_in_cooling))
    put("integral_never", float(p.integral_reset == "never"))
    put("anti_windup", float(p.anti_windup == "clamp"))
    put("stress_algebraic", float(p.stress_law == "algebraic"))
    put("stick_initial_only", float(p.friction_sticking == "initial-only"))
    put("damping_enabled", float(p.damping_switch == "enabled"))
    pu, _, _, pl, _, _ = both_tendons(th0, r, a0u, a0l, p.a1_m, p.a2_m, p.a4_m, p.a5_m)
    put("path0_u", pu)
    put("path0_l", pl)
    put("sigma0_u", p.spring_K_N_m * x0_u / S_w)
    put("sigma0_l", p.spring_K_N_m * x0_l / S_w)
    # algebraic law: total strain = elastic strain (wire + spring) + eps_R xi at the start
    K_D = youngs_modulus(p.xi_init, p.D_A_Pa, p.D_M_Pa) * S_w / p.wire_length_m
    for side, x0 in (("u", x0_u), ("l", x0_l)):
        eps_el0 = (x0 + x0 * p.spring_K_N_m / K_D) / p.wire_length_m
        put(f"eps_tot0_{side}", eps_el0 + p.eps_R * p.xi_init)
    return v
