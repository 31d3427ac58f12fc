"""Right-hand side of the coupled model (Table I), assembled from :mod:`smafinger.model`.

State y = [theta, omega, T_U, T_L, sigma_U, sigma_L, integral of error, E_U, E_L].
Discrete inputs, held over a sub-step, in ``d`` (indices ``D_*``): voltages, kinetics
branch / start value / held xi per wire, heating-phase flags, stuck flag, C_DF, target.
With the algebraic stress law (authors' 2020 model) sigma is solved from theta, T and xi and
the sigma entries of y are not used.
"""

import math

from numba import njit

from ..model.constitutive import (
    equivalent_modulus,
    secant_modulus_authors,
    spring_elongation,
    spring_stiffness,
    stress_rate,
    youngs_modulus,
)
from ..model.dynamics import angular_acceleration, external_moment
from ..model.heat import temperature_rate
from ..model.kinematics import both_tendons
from ..model.kinetics import martensite_fraction
from ..model.layout import (
    P_A_F0, P_A_S0, P_A_w, P_C_DF_c, P_C_p, P_D_A, P_D_M, P_I, P_K_S, P_L_w, P_M_DF, P_M_F0,
    P_M_S0, P_M_w, P_R_w, P_S_w, P_T_amb, P_a0_l, P_a0_u, P_a1, P_a2, P_a4, P_a5, P_c_A,
    P_c_M, P_d_CM, P_eps_R, P_eps_tot0_l, P_eps_tot0_u, P_fact, P_g, P_h0_c, P_h0_h, P_h2_c,
    P_h2_h, P_m, P_path0_l, P_path0_u, P_r, P_stress_algebraic, P_xlim_l, P_xlim_u,
)

N_STATE = 9  # _axpy and _rk4_sum spell out the 9 entries
Y_THETA, Y_OMEGA, Y_TU, Y_TL, Y_SU, Y_SL, Y_INT, Y_EU, Y_EL = range(N_STATE)

N_DISC = 14
(D_VU, D_VL, D_BRU, D_STU, D_XHU, D_BRL, D_STL, D_XHL, D_HEATU, D_HEATL, D_STUCK, D_CDF,
 D_THF, D_INTON) = range(N_DISC)

N_AUX = 13
(A_ME, A_XIU, A_XIL, A_SU, A_SL, A_DTU, A_DTL, A_XU, A_XL, A_BU, A_BL, A_PU, A_PL) = range(N_AUX)


@njit(cache=True, inline="always")
def wire_temperature_rate(T, V, heating, p):
    """Eq. (11) with the heating or cooling coefficients of the actuator's phase."""
    if heating:
        h0 = p[P_h0_h]
        h2 = p[P_h2_h]
    else:
        h0 = p[P_h0_c]
        h2 = p[P_h2_c]
    return temperature_rate(T, V, h0, h2, p[P_T_amb], p[P_R_w], p[P_M_w], p[P_C_p], p[P_A_w])


@njit(cache=True, inline="always")
def _xi(branch, start, held, T, sigma, p):
    return martensite_fraction(int(branch), start, held, T, sigma, p[P_A_S0], p[P_A_F0],
                               p[P_c_A], p[P_M_S0], p[P_M_F0], p[P_c_M])


@njit(cache=True)
def algebraic_stress(eps_total, T, branch, start, held, p, xlim):
    """Authors' 2020 law: sigma = D_eq (eps - eps_R xi), solved with xi(T, sigma).

    Fixed-point iteration (the xi-sigma coupling is weak, contraction about 0.05).
    Returns (sigma, xi, spring elongation).
    """
    sigma = 0.0
    xi = 0.0
    x_s = 0.0
    for _ in range(12):
        xi = _xi(branch, start, held, T, sigma, p)[0]
        eps_el = eps_total - p[P_eps_R] * xi
        if eps_el <= 0.0:
            sigma_new = 0.0
            x_s = 0.0
        else:
            D = youngs_modulus(xi, p[P_D_A], p[P_D_M])
            D_eq, x_s = secant_modulus_authors(eps_el, D, p[P_K_S], xlim, p[P_fact],
                                               p[P_S_w], p[P_L_w])
            sigma_new = D_eq * eps_el
        if abs(sigma_new - sigma) <= 1e-9 * (1.0 + abs(sigma_new)):
            sigma = sigma_new
            break
        sigma = sigma_new
    xi = _xi(branch, start, held, T, sigma, p)[0]
    return sigma, xi, x_s


@njit(cache=True, inline="always")
def rate_wire(sigma, T, dT, branch, start, held, dpath, omega, p, xlim):
    """Rate-form law (Eq. 7b) for one wire: (dsigma/dt, xi, spring elongation)."""
    xi, xT, xs = _xi(branch, start, held, T, sigma, p)
    D = youngs_modulus(xi, p[P_D_A], p[P_D_M])
    x_s = spring_elongation(sigma * p[P_S_w], p[P_K_S], xlim, p[P_fact])
    K_s = spring_stiffness(x_s, p[P_K_S], xlim, p[P_fact])
    D_eq = equivalent_modulus(K_s, D, p[P_S_w], p[P_L_w])
    deps = dpath * omega / p[P_L_w]  # Eq. (6): Delta eps = Delta path / L_w
    return stress_rate(D_eq, deps, p[P_eps_R], xT, xs, dT, sigma), xi, x_s


@njit(cache=True, inline="always")
def kinematics(theta, p):
    """All that :func:`evaluate` needs of the angle: (path_U, dpath_U, arm_U, path_L,
    dpath_L, arm_L, cos theta).

    A pure function of theta: the engine reuses it while theta does not change (a stuck
    joint), which gives the same bits as recomputing it.
    """
    pu, du, bu, pl, dl, bl = both_tendons(theta, p[P_r], p[P_a0_u], p[P_a0_l], p[P_a1],
                                          p[P_a2], p[P_a4], p[P_a5])
    return pu, du, bu, pl, dl, bl, math.cos(theta)


@njit(cache=True, inline="always")
def evaluate(y, d, p, kin):
    """(dy/dt, aux): the derivative of state y and M_E, xi, sigma, dT/dt, spring elongation,
    arms, paths (indices ``A_*``); ``kin`` = ``kinematics(y[Y_THETA], p)``.

    ``y`` (N_STATE values), ``d`` (N_DISC) and ``p`` (the N_PARAMS packed parameters) are
    tuples of floats (the kernel makes them with numba's ``to_fixed_tuple``), passed and
    returned by value: no arrays, hence no reference counting, on the path run at every
    stage.
    """
    theta = y[Y_THETA]
    omega = y[Y_OMEGA]
    pu, du, bu, pl, dl, bl, cos_theta = kin
    Tu = y[Y_TU]
    Tl = y[Y_TL]
    Vu = d[D_VU]
    Vl = d[D_VL]
    dTu = wire_temperature_rate(Tu, Vu, d[D_HEATU] != 0.0, p)
    dTl = wire_temperature_rate(Tl, Vl, d[D_HEATL] != 0.0, p)
    if p[P_stress_algebraic] != 0.0:
        eps_u = p[P_eps_tot0_u] + (pu - p[P_path0_u]) / p[P_L_w]
        eps_l = p[P_eps_tot0_l] + (pl - p[P_path0_l]) / p[P_L_w]
        su, xiu, xsu = algebraic_stress(eps_u, Tu, d[D_BRU], d[D_STU], d[D_XHU], p, p[P_xlim_u])
        sl, xil, xsl = algebraic_stress(eps_l, Tl, d[D_BRL], d[D_STL], d[D_XHL], p, p[P_xlim_l])
        dsu = 0.0
        dsl = 0.0
    else:
        su = y[Y_SU]
        sl = y[Y_SL]
        dsu, xiu, xsu = rate_wire(su, Tu, dTu, d[D_BRU], d[D_STU], d[D_XHU], du, omega, p,
                                  p[P_xlim_u])
        dsl, xil, xsl = rate_wire(sl, Tl, dTl, d[D_BRL], d[D_STL], d[D_XHL], dl, omega, p,
                                  p[P_xlim_l])
    M_E = external_moment(su, sl, bu, bl, cos_theta, p[P_S_w], p[P_m], p[P_g], p[P_d_CM])
    stuck = d[D_STUCK] != 0.0
    R = p[P_R_w] * p[P_L_w]  # whole-wire resistance for the electrical energy
    dy = (
        0.0 if stuck else omega,                                                  # Y_THETA
        angular_acceleration(M_E, omega, stuck, p[P_I], p[P_M_DF], d[D_CDF]),     # Y_OMEGA
        dTu,                                                                      # Y_TU
        dTl,                                                                      # Y_TL
        dsu,                                                                      # Y_SU
        dsl,                                                                      # Y_SL
        (d[D_THF] - theta) * d[D_INTON],                                          # Y_INT
        Vu * Vu / R,                                                              # Y_EU
        Vl * Vl / R,                                                              # Y_EL
    )
    aux = (M_E, xiu, xil, su, sl, dTu, dTl, xsu, xsl, bu, bl, pu, pl)  # A_* order
    return dy, aux


@njit(cache=True, inline="always")
def _axpy(y, c, k):
    """y + c k, element-wise over the N_STATE entries (same operations as the loop form)."""
    return (y[0] + c * k[0], y[1] + c * k[1], y[2] + c * k[2], y[3] + c * k[3],
            y[4] + c * k[4], y[5] + c * k[5], y[6] + c * k[6], y[7] + c * k[7],
            y[8] + c * k[8])


@njit(cache=True, inline="always")
def _rk4_sum(y, c, k1, k2, k3, k4):
    """y + c (k1 + 2 k2 + 2 k3 + k4), element-wise."""
    return (y[0] + c * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
            y[1] + c * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
            y[2] + c * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2]),
            y[3] + c * (k1[3] + 2.0 * k2[3] + 2.0 * k3[3] + k4[3]),
            y[4] + c * (k1[4] + 2.0 * k2[4] + 2.0 * k3[4] + k4[4]),
            y[5] + c * (k1[5] + 2.0 * k2[5] + 2.0 * k3[5] + k4[5]),
            y[6] + c * (k1[6] + 2.0 * k2[6] + 2.0 * k3[6] + k4[6]),
            y[7] + c * (k1[7] + 2.0 * k2[7] + 2.0 * k3[7] + k4[7]),
            y[8] + c * (k1[8] + 2.0 * k2[8] + 2.0 * k3[8] + k4[8]))


@njit(cache=True, inline="always")
def _kin_at(theta, theta_prev, kin_prev, p):
    """kinematics(theta), reusing ``kin_prev`` (that of ``theta_prev``) if theta is unchanged."""
    if theta == theta_prev:
        return kin_prev
    return kinematics(theta, p)


@njit(cache=True, inline="always")
def integrate_rest(method, y, h, d, p, k1, kin):
    """y advanced by h: explicit Euler (order 1) or classical RK4 (order 4).

    ``k1`` = f(y) must already be known (the engine evaluates it at every sub-step start
    for the discrete-state decisions), ``kin`` = kinematics(y[Y_THETA]). ``y``, ``d``,
    ``p``, ``k1`` are tuples (see :func:`evaluate`); returns the new state tuple.
    """
    if method == 0:
        return _axpy(y, h, k1)
    half = 0.5 * h
    y2 = _axpy(y, half, k1)
    kin2 = _kin_at(y2[Y_THETA], y[Y_THETA], kin, p)
    k2 = evaluate(y2, d, p, kin2)[0]
    y3 = _axpy(y, half, k2)
    kin3 = _kin_at(y3[Y_THETA], y2[Y_THETA], kin2, p)
    k3 = evaluate(y3, d, p, kin3)[0]
    y4 = _axpy(y, h, k3)
    kin4 = _kin_at(y4[Y_THETA], y3[Y_THETA], kin3, p)
    k4 = evaluate(y4, d, p, kin4)[0]
    return _rk4_sum(y, h / 6.0, k1, k2, k3, k4)
