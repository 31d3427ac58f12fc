"""Eqs. (9)-(10): cosine phase kinetics with stress-shifted temperatures and minor loops.

Heating (Eq. 9): A_S = A_S0 + sigma/c_A, A_F = A_F0 + sigma/c_A and
    xi = xi_M0/2 {cos[a_A (T - A_S0) + b_A sigma] + 1} = xi_M0 g_A(T, sigma),
    a_A = pi/(A_F0 - A_S0), b_A = -a_A/c_A; g_A = 1 below A_S, 0 above A_F.
Cooling (Eq. 10): M_S = M_S0 + sigma/c_M, M_F = M_F0 + sigma/c_M and
    xi = (1 - xi_A0)/2 cos[a_M (T - M_F0) + b_M sigma] + (1 + xi_A0)/2
       = xi_A0 + (1 - xi_A0) g_M(T, sigma),  g_M = 0 above M_S, 1 below M_F.

Branch: heating while dT/dt > 0, cooling while dT/dt < 0, xi held when dT/dt = 0.
Minor loops (MODEL-NOTES): the start value of the branch being entered (xi_M0 or xi_A0) is
re-solved from the current xi, T and sigma, so xi is continuous through every reversal.
For a major loop xi_M0 = 1 and xi_A0 = 0.
"""

import math
from typing import NamedTuple

from numba import njit

HOLD = 0
HEATING = 1
COOLING = 2


class Branch(NamedTuple):
    """A wire's kinetics branch, held over a sub-step (minor loops: MODEL-NOTES)."""

    branch: int  #: HOLD, HEATING or COOLING
    start: float  #: xi_M0 on the heating branch (Eq. 9b), xi_A0 on the cooling branch (Eq. 10b)
    held: float  #: xi on the hold branch
    turn_C: float  #: extreme temperature since the last change (dead-band rule)


def initial_branch(xi_init: float, T_init_C: float) -> Branch:
    """A wire at rest: on the hold branch at its initial xi."""
    return Branch(HOLD, xi_init, xi_init, T_init_C)


@njit(cache=True, inline="always")
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


@njit(cache=True, inline="always")
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


@njit(cache=True, inline="always")
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


@njit(cache=True, inline="always")
def xi_on_branch(b, T, sigma, wire):
    """xi and its partials (dxi/dT, dxi/dsigma) of a wire on branch ``b`` (Eqs. 9b, 10b)."""
    return martensite_fraction(b.branch, b.start, b.held, T, sigma, wire.A_S0_C, wire.A_F0_C,
                               wire.c_A_Pa_per_C, wire.M_S0_C, wire.M_F0_C, wire.c_M_Pa_per_C)


@njit(cache=True)
def enter_branch(b, new_branch, turn_C, xi_now, T, sigma, wire):
    """The branch record on entering ``new_branch`` with xi = ``xi_now`` at (T, sigma).

    The start value is re-solved so that the new branch passes through xi_now (continuous xi
    through the reversal); on the hold branch xi stays at xi_now.
    """
    if new_branch == HOLD:
        return Branch(new_branch, b.start, xi_now, turn_C)
    start = branch_start(new_branch, xi_now, T, sigma, wire.A_S0_C, wire.A_F0_C, wire.c_A_Pa_per_C,
                         wire.M_S0_C, wire.M_F0_C, wire.c_M_Pa_per_C)
    return Branch(new_branch, start, b.held, turn_C)
