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

N_STATE = 9
Y_THETA, Y_OMEGA, Y_TU, Y_TL, Y_SU, Y_SL, Y_INT, Y_EU, Y_EL = range(N_STATE)

N_DISC = 14
(D_VU, D_VL, D_BRU, D_STU, D_XHU, D_BRL, D_STL, D_XHL, D_HEATU, D_HEATL, D_STUCK, D_CDF,
 D_THF, D_INTON) = range(N_DISC)

N_AUX = 13
(A_ME, A_XIU, A_XIL, A_SU, A_SL, A_DTU, A_DTL, A_XU, A_XL, A_BU, A_BL, A_PU, A_PL) = range(N_AUX)


@njit(cache=True)
def wire_temperature_rate(T, V, heating, p):
    """Eq. (11) with the heating or cooling coefficients of the actuator's phase."""
    if heating:
        h0 = p[P_h0_h]
        h2 = p[P_h2_h]
    else:
        h0 = p[P_h0_c]
        h2 = p[P_h2_c]
    return temperature_rate(T, V, h0, h2, p[P_T_amb], p[P_R_w], p[P_M_w], p[P_C_p], p[P_A_w])


@njit(cache=True)
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


@njit(cache=True)
def rate_wire(sigma, T, dT, branch, start, held, dpath, omega, p, xlim):
    """Rate-form law (Eq. 7b) for one wire: (dsigma/dt, xi, spring elongation)."""
    xi, xT, xs = _xi(branch, start, held, T, sigma, p)
    D = youngs_modulus(xi, p[P_D_A], p[P_D_M])
    x_s = spring_elongation(sigma * p[P_S_w], p[P_K_S], xlim, p[P_fact])
    K_s = spring_stiffness(x_s, p[P_K_S], xlim, p[P_fact])
    D_eq = equivalent_modulus(K_s, D, p[P_S_w], p[P_L_w])
    deps = dpath * omega / p[P_L_w]  # Eq. (6): Delta eps = Delta path / L_w
    return stress_rate(D_eq, deps, p[P_eps_R], xT, xs, dT, sigma), xi, x_s


@njit(cache=True)
def evaluate(y, d, p, dy, aux):
    """dy/dt into ``dy``; M_E, xi, sigma, dT/dt, spring elongation, arms, paths into ``aux``."""
    theta = y[Y_THETA]
    omega = y[Y_OMEGA]
    pu, du, bu, pl, dl, bl = both_tendons(theta, p[P_r], p[P_a0_u], p[P_a0_l], p[P_a1],
                                          p[P_a2], p[P_a4], p[P_a5])
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
    M_E = external_moment(su, sl, bu, bl, math.cos(theta), p[P_S_w], p[P_m], p[P_g], p[P_d_CM])
    stuck = d[D_STUCK] != 0.0
    dy[Y_THETA] = 0.0 if stuck else omega
    dy[Y_OMEGA] = angular_acceleration(M_E, omega, stuck, p[P_I], p[P_M_DF], d[D_CDF])
    dy[Y_TU] = dTu
    dy[Y_TL] = dTl
    dy[Y_SU] = dsu
    dy[Y_SL] = dsl
    dy[Y_INT] = (d[D_THF] - theta) * d[D_INTON]
    R = p[P_R_w] * p[P_L_w]  # whole-wire resistance for the electrical energy
    dy[Y_EU] = Vu * Vu / R
    dy[Y_EL] = Vl * Vl / R
    aux[A_ME] = M_E
    aux[A_XIU] = xiu
    aux[A_XIL] = xil
    aux[A_SU] = su
    aux[A_SL] = sl
    aux[A_DTU] = dTu
    aux[A_DTL] = dTl
    aux[A_XU] = xsu
    aux[A_XL] = xsl
    aux[A_BU] = bu
    aux[A_BL] = bl
    aux[A_PU] = pu
    aux[A_PL] = pl


@njit(cache=True)
def integrate_rest(method, y, h, d, p, work, aux):
    """Advance y in place by h: explicit Euler (order 1) or classical RK4 (order 4).

    ``work[0]`` must already hold k1 = f(y) (the engine evaluates it at every sub-step
    start for the discrete-state decisions).
    """
    n = y.shape[0]
    k1 = work[0]
    if method == 0:
        for i in range(n):
            y[i] += h * k1[i]
        return
    k2 = work[1]
    k3 = work[2]
    k4 = work[3]
    yt = work[4]
    for i in range(n):
        yt[i] = y[i] + 0.5 * h * k1[i]
    evaluate(yt, d, p, k2, aux)
    for i in range(n):
        yt[i] = y[i] + 0.5 * h * k2[i]
    evaluate(yt, d, p, k3, aux)
    for i in range(n):
        yt[i] = y[i] + h * k3[i]
    evaluate(yt, d, p, k4, aux)
    for i in range(n):
        y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
