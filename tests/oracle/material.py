"""Eqs. (7)-(10) in plain Python: moduli, the spring-slack tendon, the major kinetics curves, stress laws.

Written from the paper and ``shared/MODEL-NOTES.md``, not from ``smafinger.model``; the
nonlinear equations are solved with :func:`scipy.optimize.brentq`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import brentq


@dataclass(frozen=True)
class Transformation:
    """Transformation temperatures at zero stress and their stress slopes (Table II)."""

    A_S0: float
    A_F0: float
    M_S0: float
    M_F0: float
    c_A: float
    c_M: float


@dataclass(frozen=True)
class SpringSlack:
    """The spring-slack element in series with a tendon (MODEL-NOTES, "Springs and slack")."""

    K: float  #: K_S [N/m]
    knee: float  #: elongation [m] beyond which the slack stiffens the spring
    per_mm: float  #: cosh factor [1/mm]


# --------------------------------------------------------------------------------------------
# Eqs. (9)-(10): martensite fraction on each curve, with its partial derivatives
# --------------------------------------------------------------------------------------------
def heating_curve(T: float, sigma: float, m: Transformation) -> tuple[float, float, float]:
    """(g, dg/dT, dg/dsigma) with xi = xi_M0 g on heating, Eq. (9).

    g = {cos[a_A (T - A_S0) + b_A sigma] + 1} / 2, a_A = pi/(A_F0 - A_S0), b_A = -a_A/c_A,
    between A_S = A_S0 + sigma/c_A and A_F = A_F0 + sigma/c_A; 1 below A_S, 0 above A_F.
    """
    if T < m.A_S0 + sigma / m.c_A:
        return 1.0, 0.0, 0.0
    if T > m.A_F0 + sigma / m.c_A:
        return 0.0, 0.0, 0.0
    a = math.pi / (m.A_F0 - m.A_S0)
    b = -a / m.c_A
    arg = a * (T - m.A_S0) + b * sigma
    s = math.sin(arg)
    return 0.5 * (math.cos(arg) + 1.0), -0.5 * a * s, -0.5 * b * s


def cooling_curve(T: float, sigma: float, m: Transformation) -> tuple[float, float, float]:
    """(g, dg/dT, dg/dsigma) with xi = xi_A0 + (1 - xi_A0) g on cooling, Eq. (10).

    Eq. (10b): xi = (1 - xi_A0)/2 cos[a_M (T - M_F0) + b_M sigma] + (1 + xi_A0)/2, with
    a_M = pi/(M_F0 - M_S0), b_M = -a_M/c_M, between M_F and M_S; g = 1 below M_F, 0 above M_S.
    """
    if T > m.M_S0 + sigma / m.c_M:
        return 0.0, 0.0, 0.0
    if T < m.M_F0 + sigma / m.c_M:
        return 1.0, 0.0, 0.0
    a = math.pi / (m.M_F0 - m.M_S0)
    b = -a / m.c_M
    arg = a * (T - m.M_F0) + b * sigma
    s = math.sin(arg)
    return 0.5 * (math.cos(arg) + 1.0), -0.5 * a * s, -0.5 * b * s


# --------------------------------------------------------------------------------------------
# Eqs. (7)-(8): moduli and the spring-slack tendon
# --------------------------------------------------------------------------------------------
def youngs_modulus(xi: float, D_A: float, D_M: float) -> float:
    """D = D_A + xi (D_M - D_A), Eq. (7a)."""
    return D_A + xi * (D_M - D_A)


def spring_stiffness(x: float, s: SpringSlack) -> float:
    """K_s,eff = K_S + cosh(f dx) - 1 [N/m], dx = 1000 (x - knee) in mm, K_S below the knee."""
    dx_mm = (x - s.knee) * 1e3
    return s.K if dx_mm <= 0.0 else s.K + math.cosh(s.per_mm * dx_mm) - 1.0


def spring_stiffness_slope(x: float, s: SpringSlack) -> float:
    """dK_s,eff/dx [N/m^2]: 1000 f sinh(f dx) beyond the knee, 0 below it."""
    dx_mm = (x - s.knee) * 1e3
    return 0.0 if dx_mm <= 0.0 else 1e3 * s.per_mm * math.sinh(s.per_mm * dx_mm)


def spring_force(x: float, s: SpringSlack) -> float:
    """Tension of the spring at elongation x: the integral of K_s,eff from 0 to x [N]."""
    if x <= 0.0:
        return 0.0
    if x <= s.knee or s.per_mm == 0.0:
        return s.K * x
    # integral of cosh(f 1000 (x' - knee)) - 1 over [knee, x]
    u = s.per_mm * 1e3 * (x - s.knee)
    return s.K * x + (math.sinh(u) / (s.per_mm * 1e3) - (x - s.knee))


def spring_elongation(F: float, s: SpringSlack) -> float:
    """The spring's elongation under tension F >= 0 (inverse of :func:`spring_force`, brentq)."""
    if F <= 0.0:
        return 0.0
    lin = F / s.K
    if lin <= s.knee or s.per_mm == 0.0 or spring_force(lin, s) <= F:  # (the last: stiffening below round-off)
        return lin
    # the stiffening spring stretches less than the linear one, and beyond the knee
    return brentq(lambda x: spring_force(x, s) - F, s.knee, lin, xtol=1e-300, rtol=1e-15, maxiter=200)


def series_modulus(K_s: float, D: float, S_w: float, L_w: float) -> float:
    """D_eq = K_s D / (K_D + K_s), K_D = D S_w / L_w: wire and spring in series, Eq. (8)."""
    K_D = D * S_w / L_w
    return K_s * D / (K_D + K_s)


# --------------------------------------------------------------------------------------------
# the two stress laws
# --------------------------------------------------------------------------------------------
def rate_law(D_eq: float, strain_rate: float, eps_R: float, xi_T: float, xi_s: float) -> tuple[float, float]:
    """Eq. (7b) with theta_T = 0 as sigma' = s_free + s_T T': returns (s_free, s_T).

    Eq. (7b) with eps_t = xi eps_R and Omega = -eps_R D: D eps_t' + Omega xi' = 0, so
    sigma' = D_eq (eps_e' + eps_s') = D_eq (eps' - eps_R xi'), and xi' = xi_T T' + xi_s sigma'
    along the kinetics branch; solved for sigma'. (A slack tendon does not push: the caller
    floors the rate at sigma <= 0.)
    """
    den = 1.0 + D_eq * eps_R * xi_s
    return D_eq * strain_rate / den, -D_eq * eps_R * xi_T / den


def secant_law(eps_el: float, D: float, spring: SpringSlack | None, S_w: float, L_w: float) -> tuple[float, float]:
    """(D_eq, spring elongation) at elastic strain eps_el for the algebraic law (authors' 2020).

    The elastic elongation L_w eps_el splits between wire (K_D) and spring (K_S) as two springs
    in series: the spring takes K_D / (K_D + K_S) of it; the slack stiffening at that elongation
    gives K_s,eff and D_eq (Eq. 8). A rigid wire (no spring): D_eq = D.
    """
    if spring is None:
        return D, 0.0
    K_D = D * S_w / L_w
    x_spring = L_w * eps_el * K_D / (K_D + spring.K)
    return series_modulus(spring_stiffness(x_spring, spring), D, S_w, L_w), x_spring


def secant_stress(eps_el: float, xi: float, D_A: float, D_M: float, spring: SpringSlack | None, S_w: float,
                  L_w: float) -> float:
    """F(eps_el, xi) = D_eq eps_el: the stress an elastic strain implies at martensite fraction xi."""
    if eps_el <= 0.0:
        return 0.0
    return secant_law(eps_el, youngs_modulus(xi, D_A, D_M), spring, S_w, L_w)[0] * eps_el


def algebraic_stress(eps: float, T: float, branch, m: Transformation, D_A: float, D_M: float,
                     eps_R: float, spring: SpringSlack | None, S_w: float, L_w: float):
    """(sigma, xi's Fraction, spring elongation) of sigma = D_eq (eps - eps_R xi(T, sigma)) (MODEL-NOTES).

    sigma and xi are solved together: the root of sigma - S(sigma), S(sigma) the stress that the
    strain implies with xi(T, sigma) on ``branch``; S decreases with sigma, so the root lies in
    [0, S(0)].
    """
    def implied(sigma):
        f = branch.fraction(T, sigma, m)
        eps_el = eps - eps_R * f.xi
        if eps_el <= 0.0:
            return 0.0, f, 0.0
        D_eq, x_s = secant_law(eps_el, youngs_modulus(f.xi, D_A, D_M), spring, S_w, L_w)
        return D_eq * eps_el, f, x_s

    top = implied(0.0)
    if top[0] <= 0.0:
        return top
    if top[0] - implied(top[0])[0] <= 0.0:  # xi does not depend on sigma here: S is constant
        sigma = top[0]
    else:
        sigma = brentq(lambda s: s - implied(s)[0], 0.0, top[0], xtol=1e-300, rtol=1e-15, maxiter=500)
    _, f, x_s = implied(sigma)
    return sigma, f, x_s


def algebraic_law(eps: float, strain_rate: float, sigma: float, f, eps_R: float, D_A: float, D_M: float,
                  spring: SpringSlack | None, S_w: float, L_w: float) -> tuple[float, float]:
    """The algebraic law's stress rate as sigma' = s_free + s_T T': returns (s_free, s_T).

    sigma = F(eps - eps_R xi, xi) with xi = xi(T, sigma) (``f``: its Fraction at the solution),
    differentiated along the motion: sigma' = F_e eps' + G (xi_T T' + xi_s sigma'),
    G = F_x - eps_R F_e (F's partials by central differences), solved for sigma'. 0 for a slack
    wire (no elastic strain). The stress is no state of this law: the rate serves the memory
    rule's driving tau = T - sigma/c (docs/hysteresis.md).
    """
    e = eps - eps_R * f.xi
    if sigma <= 0.0 or e <= 0.0:
        return 0.0, 0.0
    F = lambda e_, x_: secant_stress(e_, x_, D_A, D_M, spring, S_w, L_w)  # noqa: E731
    he, hx = 1e-6 * e, 1e-6
    F_e = (F(e + he, f.xi) - F(e - he, f.xi)) / (2.0 * he)
    F_x = (F(e, f.xi + hx) - F(e, f.xi - hx)) / (2.0 * hx)
    G = F_x - eps_R * F_e
    den = 1.0 - G * f.xi_s
    return F_e * strain_rate / den, G * f.xi_T / den
