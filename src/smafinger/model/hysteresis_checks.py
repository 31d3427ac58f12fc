"""Checkers of the properties a hysteresis rule for Eqs. (9)-(10) must hold (docs/hysteresis.md).

Each takes a sampled history (T degC, sigma Pa, xi; between samples the input moves
monotonically) and returns the sample indices where the property fails, so that a test can
assert the list is empty for the memory rule and non-empty for today's rules.

1. xi in [0, 1] and continuous (:func:`range_violations`, :func:`jump_violations`);
2. xi falls only while tau_A rises through the heating band and rises only while tau_M falls
   through the cooling band (:func:`direction_violations`);
3. g_M(tau_M) <= xi <= g_A(tau_A) (:func:`loop_violations`);
4. return-point memory (a comparison of two histories: ``tests/test_hysteresis.py``);
5. ripple of amplitude d moves xi by at most C d (:func:`ripple_gain`).
"""

import math

import numpy as np

from .hysteresis import major_loop

TOL = 1e-12


def _taus(T, sigma, m):
    T = np.asarray(T, dtype=float)
    sigma = np.asarray(sigma, dtype=float)
    return T - sigma / m.c_A_Pa_per_C, T - sigma / m.c_M_Pa_per_C


def range_violations(xi, tol=TOL):
    """Indices where xi is outside [0, 1] (by more than ``tol``)."""
    xi = np.asarray(xi, dtype=float)
    return np.flatnonzero((xi < -tol) | (xi > 1.0 + tol))


def jump_violations(xi, xi_step_end, tol=TOL):
    """Indices where the state update at a sample changed xi (a jump).

    ``xi_step_end[k]`` is xi at sample k from the state before the update there, ``xi[k]``
    the value after it (:class:`~smafinger.model.hysteresis_drive.HistoryResult`).
    """
    return np.flatnonzero(np.abs(np.asarray(xi) - np.asarray(xi_step_end)) > tol)


def direction_violations(T, sigma, xi, m, tol=TOL):
    """Intervals k -> k+1 (index k) where xi moved against property 2.

    A fall of xi needs tau_A to rise and [tau_A,k, tau_A,k+1] to meet the open heating band
    (A_S0, A_F0); a rise needs tau_M to fall and to meet the cooling band (M_F0, M_S0).
    """
    tA, tM = _taus(T, sigma, m)
    dxi = np.diff(np.asarray(xi, dtype=float))
    lo_A, hi_A = np.minimum(tA[:-1], tA[1:]), np.maximum(tA[:-1], tA[1:])
    lo_M, hi_M = np.minimum(tM[:-1], tM[1:]), np.maximum(tM[:-1], tM[1:])
    fall_ok = (tA[1:] > tA[:-1]) & (np.maximum(lo_A, m.A_S0_C) < np.minimum(hi_A, m.A_F0_C))
    rise_ok = (tM[1:] < tM[:-1]) & (np.maximum(lo_M, m.M_F0_C) < np.minimum(hi_M, m.M_S0_C))
    bad = ((dxi < -tol) & ~fall_ok) | ((dxi > tol) & ~rise_ok)
    return np.flatnonzero(bad)


def loop_violations(T, sigma, xi, m, tol=TOL):
    """Indices where xi is outside the major loop [g_M(tau_M), g_A(tau_A)]."""
    bad = []
    for k, (t, s, x) in enumerate(zip(np.asarray(T, float), np.asarray(sigma, float),
                                      np.asarray(xi, float))):
        gM, gA = major_loop(t, s, m)
        if x < gM - tol or x > gA + tol:
            bad.append(k)
    return np.asarray(bad, dtype=np.int64)


def ripple_gain(m):
    """C of property 5: pi (1/(A_F0 - A_S0) + 1/(M_S0 - M_F0)) per degC of tau ripple.

    pi/(2 W) is the largest slope of a major curve of band width W; a ripple of amplitude d
    leaves the running extreme of tau within 2 d of the ramp's, and a first-order branch
    through a point of the loop is no steeper than its major curve, so xi stays within
    C d of the ramp without ripple (one heating and one cooling excursion of 2 d).
    """
    return math.pi * (1.0 / (m.A_F0_C - m.A_S0_C) + 1.0 / (m.M_S0_C - m.M_F0_C))
