"""Eqs. (7)-(8): rate-form constitutive law with the spring-slack tendon in series.

Eq. (7a) with theta_T = 0 (Sec. 3), eps_t = xi eps_R and Omega = -eps_R D gives, for wire and
spring in series (Eq. 7b),

    dsigma/dt = D_eq (d eps/dt - eps_R d xi/dt),
    D_eq = K_eq L_w / S_w,  K_eq = K_s K_D / (K_s + K_D),  K_D = D S_w / L_w   (Eq. 8)

with D = D_A + xi (D_M - D_A). The spring-slack element: the spring stiffens from
``slack_band`` before the slack point (``slack`` beyond the initial elongation) as
K_s,eff = K_S + cosh(f dx) - 1 [N/m], dx in mm (MODEL-NOTES). A tendon only pulls: the
stress never goes negative.
"""

import math

from ..jit import njit


#: the largest argument of sinh and cosh that does not overflow a float: ln(2 * DBL_MAX)
SINH_MAX_ARG = 710.4758600739439


@njit(cache=True, forceinline=True)
def youngs_modulus(xi, D_A, D_M):
    """D = D_A + xi (D_M - D_A) (Eq. 7a)."""
    return D_A + xi * (D_M - D_A)


@njit(cache=True, forceinline=True)
def spring_stiffness(x, K_S, x_limit, fact):
    """K_s,eff [N/m] at spring elongation x [m]; stiffening beyond x_limit (dx in mm)."""
    dx_mm = 1000.0 * (x - x_limit)
    if dx_mm <= 0.0:
        return K_S
    return K_S + math.cosh(fact * dx_mm) - 1.0


@njit(cache=True)
def spring_force(x, K_S, x_limit, fact):
    """F_s(x) = integral of K_s,eff: K_S x + (sinh(f dx) - f dx) / (1000 f) beyond x_limit."""
    if x <= 0.0:
        return 0.0
    dx_mm = 1000.0 * (x - x_limit)
    if dx_mm <= 0.0 or fact == 0.0:
        return K_S * x
    u = fact * dx_mm
    return K_S * x + (math.sinh(u) - u) / (1000.0 * fact)


@njit(cache=True, forceinline=True)
def spring_elongation(F, K_S, x_limit, fact):
    """Inverse of :func:`spring_force` (F >= 0).

    Linear below the stiffening (compiled in place: the usual case at every RHS stage); beyond
    it :func:`_stiffened_elongation`.
    """
    if F <= 0.0:
        return 0.0
    x = F / K_S
    if x <= x_limit or fact == 0.0:
        return x
    return _stiffened_elongation(F, K_S, x_limit, fact, x)


@njit(cache=True)
def _stiffened_elongation(F, K_S, x_limit, fact, x):
    """:func:`spring_elongation` beyond the stiffening, from the linear guess x = F / K_S.

    Newton from the linear guess (a few iterations where the slack has not stiffened the spring
    much); far up the cosh stiffening Newton from there moves too little per iteration, so if it
    has not converged in 60 the root is bracketed and found by bisection-safeguarded Newton.
    A guess so far up that sinh overflows goes to the bracket at once (compiled, the overflow
    gave inf and Newton NaN, which ended there too; plain Python raised OverflowError).
    """
    if fact * 1000.0 * (x - x_limit) > SINH_MAX_ARG:
        return _spring_elongation_bracketed(F, K_S, x_limit, fact)
    for _ in range(60):
        r = spring_force(x, K_S, x_limit, fact) - F
        k = spring_stiffness(x, K_S, x_limit, fact)
        step = r / k
        x -= step
        if abs(step) < 1e-15:
            return x
    return _spring_elongation_bracketed(F, K_S, x_limit, fact)


@njit(cache=True)
def _spring_elongation_bracketed(F, K_S, x_limit, fact):
    """The root of spring_force(x) = F beyond x_limit, bracketed (spring_force increases with x)."""
    lo = max(x_limit, 0.0)
    hi = lo + 1e-3
    while spring_force(hi, K_S, x_limit, fact) < F:
        lo, hi = hi, lo + 2.0 * (hi - lo)
    x = 0.5 * (lo + hi)
    for _ in range(200):
        r = spring_force(x, K_S, x_limit, fact) - F
        if r > 0.0:
            hi = x
        else:
            lo = x
        x_new = x - r / spring_stiffness(x, K_S, x_limit, fact)
        if not (lo < x_new < hi):
            x_new = 0.5 * (lo + hi)
        if abs(x_new - x) <= 1e-15 * (1.0 + abs(x)):
            return x_new
        x = x_new
    return x


@njit(cache=True, forceinline=True)
def equivalent_modulus(K_s, D, S_w, L_w):
    """D_eq = K_eq L_w / S_w with K_eq = K_s K_D / (K_s + K_D) (Eq. 8) [Pa].

    A spring stiffened past what a float holds (the slack penalty's cosh overflowed: K_s = inf)
    is rigid: D_eq = D (inf / inf gave NaN; found by review, a thin wire at the largest penalty).
    """
    if K_s == math.inf:
        return D
    K_D = D * S_w / L_w
    return K_s * K_D / (K_s + K_D) * L_w / S_w


@njit(cache=True, forceinline=True)
def stress_rate(D_eq, deps_dt, eps_R, dxi_dT, dxi_dsigma, dT_dt, sigma):
    """dsigma/dt of Eq. (7b), solved together with dxi/dt = xi_T T' + xi_sigma sigma'.

    A slack tendon (sigma <= 0) cannot go into compression: its rate is then floored at 0.
    """
    rate = D_eq * (deps_dt - eps_R * dxi_dT * dT_dt) / (1.0 + D_eq * eps_R * dxi_dsigma)
    if sigma <= 0.0 and rate < 0.0:
        return 0.0
    return rate


@njit(cache=True)
def secant_modulus_authors(eps_el, D, K_S, x_limit, fact, S_w, L_w):
    """D_eq of the authors' 2020 model at total elastic strain eps_el (wire + spring).

    The elastic elongation splits between wire and spring with the linear spring stiffness;
    the spring's share sets K_s,eff, which then gives the secant D_eq (Eq. 8).
    Returns (D_eq, spring elongation [m]).
    """
    K_D = D * S_w / L_w
    x_spring = K_D * L_w * eps_el / (K_D + K_S)
    K_s = spring_stiffness(x_spring, K_S, x_limit, fact)
    return equivalent_modulus(K_s, D, S_w, L_w), x_spring


@njit(cache=True, forceinline=True)
def rate_law_modulus(wire, sigma, D):
    """(D_eq, spring elongation) of Eq. (8) for the rate law at stress sigma.

    Through a spring-slack tendon the wire and spring act in series; a wire that pulls
    directly (``series_rigid``) has D_eq = D and no spring.
    """
    if wire.series_rigid:
        return D, 0.0
    x_s = spring_elongation(sigma * wire.area_m2, wire.series_K_N_m, wire.series_limit_m,
                            wire.series_penalty_per_mm)
    K_s = spring_stiffness(x_s, wire.series_K_N_m, wire.series_limit_m, wire.series_penalty_per_mm)
    return equivalent_modulus(K_s, D, wire.area_m2, wire.wire_length_m), x_s


@njit(cache=True, forceinline=True)
def secant_modulus(wire, eps_el, D):
    """(D_eq, spring elongation) of the algebraic law at elastic strain eps_el (wire + spring)."""
    if wire.series_rigid:
        return D, 0.0
    return secant_modulus_authors(eps_el, D, wire.series_K_N_m, wire.series_limit_m,
                                  wire.series_penalty_per_mm, wire.area_m2, wire.wire_length_m)
