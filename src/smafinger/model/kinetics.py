"""Eqs. (9)-(10): cosine phase kinetics with stress-shifted temperatures and minor loops.

Heating (Eq. 9): A_S = A_S0 + sigma/c_A, A_F = A_F0 + sigma/c_A and
    xi = xi_M0/2 {cos[a_A (T - A_S0) + b_A sigma] + 1} = xi_M0 g_A(T, sigma),
    a_A = pi/(A_F0 - A_S0), b_A = -a_A/c_A; g_A = 1 below A_S, 0 above A_F.
Cooling (Eq. 10): M_S = M_S0 + sigma/c_M, M_F = M_F0 + sigma/c_M and
    xi = (1 - xi_A0)/2 cos[a_M (T - M_F0) + b_M sigma] + (1 + xi_A0)/2
       = xi_A0 + (1 - xi_A0) g_M(T, sigma),  g_M = 0 above M_S, 1 below M_F.

These are the major curves and the legacy branch rules (the authors' 2020 model: heating while
dT/dt > 0, cooling while dT/dt < 0, xi held when dT/dt = 0, the start value of the branch being
entered re-solved from the current xi so that xi is continuous; smafinger 0.1's dead band).
Minor loops with return-point memory, the default, and the engine's interface to all the
rules are in :mod:`smafinger.model.hysteresis`.
"""

import math

from ..jit import njit

HOLD = 0
HEATING = 1
COOLING = 2


@njit(cache=True, forceinline=True)
def g_heating(T, sigma, A_S0, A_F0, c_A):
    """g_A and its partial derivatives (d/dT, d/dsigma) of Eq. (9)."""
    shift = sigma / c_A
    A_S = A_S0 + shift
    A_F = A_F0 + shift
    if T <= A_S:
        return 1.0, 0.0, 0.0
    if T >= A_F:
        return 0.0, 0.0, 0.0
    a = math.pi / (A_F0 - A_S0)
    arg = a * (T - A_S)
    g = 0.5 * (math.cos(arg) + 1.0)
    dg_dT = -0.5 * a * math.sin(arg)
    return g, dg_dT, -dg_dT / c_A


@njit(cache=True, forceinline=True)
def g_cooling(T, sigma, M_S0, M_F0, c_M):
    """g_M and its partial derivatives (d/dT, d/dsigma) of Eq. (10)."""
    shift = sigma / c_M
    M_S = M_S0 + shift
    M_F = M_F0 + shift
    if T >= M_S:
        return 0.0, 0.0, 0.0
    if T <= M_F:
        return 1.0, 0.0, 0.0
    a = math.pi / (M_S0 - M_F0)
    arg = a * (T - M_F)
    g = 0.5 * (math.cos(arg) + 1.0)
    dg_dT = -0.5 * a * math.sin(arg)
    return g, dg_dT, -dg_dT / c_M


#: added to the polynomial bounds below: far above the rounding of cos and of the polynomial
BOUND_MARGIN = 1e-9


@njit(cache=True, forceinline=True)
def g_cooling_upper_bound(T, sigma, M_S0, M_F0, c_M):
    """A number >= g_M of Eq. (10) as :func:`g_cooling` computes it, without a cosine.

    The same branches as ``g_cooling`` (0 above M_S, 1 below M_F, the same bits); in the band
    (1 + cos u)/2 <= 1 - u^2/4 + u^4/48 (cos u <= 1 - u^2/2 + u^4/24 for every real u), plus
    :data:`BOUND_MARGIN`. ``xi >= g_cooling_upper_bound(...)`` proves ``xi >= g_M`` (also for
    NaN: both comparisons are then False).
    """
    shift = sigma / c_M
    M_S = M_S0 + shift
    M_F = M_F0 + shift
    if T >= M_S:
        return 0.0
    if T <= M_F:
        return 1.0
    u = math.pi / (M_S0 - M_F0) * (T - M_F)
    u2 = u * u
    return 1.0 - u2 / 4.0 + u2 * u2 / 48.0 + BOUND_MARGIN


@njit(cache=True, forceinline=True)
def g_heating_lower_bound(T, sigma, A_S0, A_F0, c_A):
    """A number <= g_A of Eq. (9) as :func:`g_heating` computes it, without a cosine.

    The same branches as ``g_heating`` (1 below A_S, 0 above A_F, the same bits); in the band
    (1 + cos u)/2 >= 1 - u^2/4 + u^4/48 - u^6/1440 (cos u >= 1 - u^2/2 + u^4/24 - u^6/720 for
    every real u), minus :data:`BOUND_MARGIN`. ``xi <= g_heating_lower_bound(...)`` proves
    ``xi <= g_A``.
    """
    shift = sigma / c_A
    A_S = A_S0 + shift
    A_F = A_F0 + shift
    if T <= A_S:
        return 1.0
    if T >= A_F:
        return 0.0
    u = math.pi / (A_F0 - A_S0) * (T - A_S)
    u2 = u * u
    return 1.0 - u2 / 4.0 + u2 * u2 / 48.0 - u2 * u2 * u2 / 1440.0 - BOUND_MARGIN


@njit(cache=True, forceinline=True)
def martensite_fraction(branch, start, xi_held, T, sigma, A_S0, A_F0, c_A, M_S0, M_F0, c_M):
    """xi and its partials (dxi/dT, dxi/dsigma) on a branch (Eqs. 9b, 10b).

    ``start`` is xi_M0 on the heating branch and xi_A0 on the cooling branch; on the hold
    branch xi = ``xi_held``. The result is clipped to [0, 1].
    """
    if branch == HEATING:
        g, gT, gs = g_heating(T, sigma, A_S0, A_F0, c_A)
        xi = start * g
        xT = start * gT
        xs = start * gs
    elif branch == COOLING:
        g, gT, gs = g_cooling(T, sigma, M_S0, M_F0, c_M)
        xi = start + (1.0 - start) * g
        xT = (1.0 - start) * gT
        xs = (1.0 - start) * gs
    else:
        return xi_held, 0.0, 0.0
    if xi > 1.0:
        return 1.0, 0.0, 0.0
    if xi < 0.0:
        return 0.0, 0.0, 0.0
    return xi, xT, xs


@njit(cache=True)
def branch_start(branch, xi, T, sigma, A_S0, A_F0, c_A, M_S0, M_F0, c_M):
    """Start value (xi_M0 or xi_A0) that makes the branch pass through the current xi.

    This is the minor-loop rule that keeps xi continuous through a reversal.
    """
    if branch == HEATING:
        g = g_heating(T, sigma, A_S0, A_F0, c_A)[0]
        if g > 1e-12:
            return xi / g
        return 1.0  # above A_F: the branch gives 0 whatever the start
    if branch == COOLING:
        g = g_cooling(T, sigma, M_S0, M_F0, c_M)[0]
        if g < 1.0 - 1e-12:
            return (xi - g) / (1.0 - g)
        return 0.0  # below M_F: the branch gives 1 whatever the start
    return xi


@njit(cache=True)
def next_branch(branch, dT_dt, T, turn, reversal):
    """Branch for the next step and the updated turning temperature.

    ``reversal`` = 0: the sign of dT/dt decides (MODEL-NOTES, authors' model).
    ``reversal`` > 0: the branch changes only once T has moved back by ``reversal`` from its
    extreme since the last change (``turn``), so that PWM ripple does not open minor loops.
    """
    if reversal <= 0.0:
        return branch_of(dT_dt), T
    nb = branch
    if branch == HEATING:
        if T > turn:
            turn = T
        elif T < turn - reversal:
            nb = COOLING
    elif branch == COOLING:
        if T < turn:
            turn = T
        elif T > turn + reversal:
            nb = HEATING
    else:
        if T > turn + reversal:
            nb = HEATING
        elif T < turn - reversal:
            nb = COOLING
    if nb != branch:
        turn = T
    return nb, turn


@njit(cache=True)
def branch_of(dT_dt):
    """Branch from the sign of dT/dt (MODEL-NOTES)."""
    if dT_dt > 0.0:
        return HEATING
    if dT_dt < 0.0:
        return COOLING
    return HOLD
