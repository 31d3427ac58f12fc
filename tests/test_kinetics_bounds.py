"""The cosine-free bounds of the major curves (model.kinetics) and the clamp that uses them.

``xi_on_branch`` evaluates the other major curve only where ``g_cooling_upper_bound`` /
``g_heating_lower_bound`` do not already show that the clamp to the major loop cannot bind;
these tests check the bounds against the curves as computed, and the clamp against the full
one (both curves, then min/max) on random branch records.
"""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from smafinger.model.hysteresis import MEMORY, BranchRecord, kinetics_material, xi_on_branch
from smafinger.model.kinetics import g_cooling, g_cooling_upper_bound, g_heating, g_heating_lower_bound

PAPER = kinetics_material(75.0, 110.0, 85.0, 60.0, 10.3e6, 10.3e6)  # Table II
UNEQUAL = kinetics_material(50.0, 70.0, 55.0, 30.0, 8e6, 14e6)


def _grid(m, sigma):
    """Temperatures across both bands, their edges and just beside them."""
    lo = min(m.M_F0_C, m.A_S0_C) + sigma / max(m.c_A_Pa_per_C, m.c_M_Pa_per_C) - 5.0
    hi = max(m.M_S0_C, m.A_F0_C) + sigma / min(m.c_A_Pa_per_C, m.c_M_Pa_per_C) + 5.0
    T = list(np.linspace(lo, hi, 20001))
    for edge in (m.A_S0_C + sigma / m.c_A_Pa_per_C, m.A_F0_C + sigma / m.c_A_Pa_per_C,
                 m.M_S0_C + sigma / m.c_M_Pa_per_C, m.M_F0_C + sigma / m.c_M_Pa_per_C):
        T += [edge, math.nextafter(edge, -math.inf), math.nextafter(edge, math.inf)]
    return T


def test_bounds_enclose_the_curves_on_a_dense_grid():
    for m in (PAPER, UNEQUAL):
        for sigma in (0.0, 11.7e6, 150e6):
            for T in _grid(m, sigma):
                gM = g_cooling(T, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)[0]
                gA = g_heating(T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)[0]
                ub = g_cooling_upper_bound(T, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)
                lb = g_heating_lower_bound(T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)
                assert ub >= gM, (m, sigma, T)
                assert lb <= gA, (m, sigma, T)
                shift_M, shift_A = sigma / m.c_M_Pa_per_C, sigma / m.c_A_Pa_per_C
                if not m.M_F0_C + shift_M < T < m.M_S0_C + shift_M:  # outside the band: the same bits
                    assert ub == gM
                if not m.A_S0_C + shift_A < T < m.A_F0_C + shift_A:
                    assert lb == gA


def test_bounds_are_tight_enough_to_skip_the_cosine_at_the_papers_holding_point():
    # the upper wire holds near 77.8 degC, 11.7 MPa on its heating branch at xi ~ 0.86: both
    # bands; the bound must let xi_on_branch skip g_M there (else the change buys nothing)
    m = PAPER
    ub = g_cooling_upper_bound(77.8, 11.7e6, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)
    assert 0.0 < ub < 0.86
    lb = g_heating_lower_bound(77.8, 11.7e6, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)
    assert 0.5 < lb < 1.0


def _full_clamp(rec, T, sigma, m):
    """The clamp with both curves always evaluated (the operations before the bounds)."""
    gA, gAT, gAs = g_heating(T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)
    gM, gMT, gMs = g_cooling(T, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)
    if rec.direction > 0:
        g, gT, gs = gA, gAT, gAs
        tau = T - sigma / m.c_A_Pa_per_C
        back, past = tau < rec.lim_tau, tau >= rec.target_tau
    else:
        g, gT, gs = gM, gMT, gMs
        tau = T - sigma / m.c_M_Pa_per_C
        back, past = tau > rec.lim_tau, tau <= rec.target_tau
    if back:
        x0, g0, b = rec.x0, rec.g0, rec.slope
        g, gT, gs = rec.lim_g, 0.0, 0.0
    elif past:
        x0, g0, b = rec.parent_x0, rec.parent_g0, rec.parent_slope
    else:
        x0, g0, b = rec.x0, rec.g0, rec.slope
    xi, xT, xs = x0 + b * (g - g0), b * gT, b * gs
    if xi < gM:
        xi, xT, xs = gM, gMT, gMs
    if xi > gA:
        xi, xT, xs = gA, gAT, gAs
    return xi, xT, xs


unit = st.floats(-0.2, 1.2)


@settings(max_examples=400, deadline=None)
@given(d=st.sampled_from([1, -1]), x0=unit, g0=unit, slope=st.floats(0.0, 3.0), lim_tau=st.floats(40.0, 120.0),
       lim_g=unit, target=st.floats(40.0, 120.0), T=st.floats(40.0, 130.0), sigma=st.floats(0.0, 200e6),
       unequal=st.booleans())
def test_clamp_equals_the_full_clamp(d, x0, g0, slope, lim_tau, lim_g, target, T, sigma, unequal):
    m = UNEQUAL if unequal else PAPER
    rec = BranchRecord(MEMORY, d, x0, g0, slope, lim_tau, lim_g, target, 0.5, x0, g0, slope, 0.0, 0.0, 0, 0)
    got = xi_on_branch(rec, T, sigma, m)
    want = _full_clamp(rec, T, sigma, m)
    assert [np.float64(v).tobytes() for v in got] == [np.float64(v).tobytes() for v in want]


@settings(max_examples=400, deadline=None)
@given(d=st.sampled_from([1, -1]), eps=st.floats(-0.08, 0.08), T=st.floats(55.0, 115.0),
       sigma=st.floats(0.0, 50e6), unequal=st.booleans())
def test_clamp_equals_the_full_clamp_next_to_the_other_curve(d, eps, T, sigma, unequal):
    # a flat branch (slope 0) at xi = the other curve's value + eps: where the bound decides
    m = UNEQUAL if unequal else PAPER
    if d > 0:
        other = g_cooling(T, sigma, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)[0]
    else:
        other = g_heating(T, sigma, m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C)[0]
    x0 = other + eps
    rec = BranchRecord(MEMORY, d, x0, 0.5, 0.0, -math.inf * d, 0.5, math.inf * d, 0.5, x0, 0.5, 0.0,
                       0.0, 0.0, 0, 0)
    got = xi_on_branch(rec, T, sigma, m)
    want = _full_clamp(rec, T, sigma, m)
    assert [np.float64(v).tobytes() for v in got] == [np.float64(v).tobytes() for v in want]
