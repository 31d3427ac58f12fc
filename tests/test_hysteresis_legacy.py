"""Today's rules under the hysteresis interface reproduce model/kinetics.py to the bit, and
the memory rule's first-order reversal curves are the paper's scaled curves (Eqs. 9b, 10b)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from smafinger.model.hysteresis import (
    AUTHORS2020, DEADBAND, drive_direction, initial_record, kinetics_material, major_loop,
    new_stack, update_memory, xi_on_branch,
)
from smafinger.model.hysteresis_drive import xi_history
from smafinger.model.kinetics import (
    COOLING, HEATING, HOLD, branch_start, martensite_fraction, next_branch,
)

PAPER = kinetics_material(75.0, 110.0, 85.0, 60.0, 10.3e6, 10.3e6)


def kinetics_args(m):
    return (m.A_S0_C, m.A_F0_C, m.c_A_Pa_per_C, m.M_S0_C, m.M_F0_C, m.c_M_Pa_per_C)


def today(T, S, m, xi_init, reversal):
    """The engine's current kinetics loop (engine/kernel.py ``_update_branch`` and rhs.py
    ``_xi``), sampled like ``xi_history``: (xi, dxi/dT, dxi/dsigma) after each update."""
    args = kinetics_args(m)
    br, st_, xh, turn = HOLD, xi_init, xi_init, T[0]
    out = np.empty((T.size, 3))
    dT = 0.0
    for k in range(T.size):
        if k + 1 < T.size:
            dT = T[k + 1] - T[k]
        nb, turn = next_branch(br, dT, T[k], turn, reversal)
        if nb != br:
            xi_now = martensite_fraction(br, st_, xh, T[k], S[k], *args)[0]
            if nb == HOLD:
                xh = xi_now
            else:
                st_ = branch_start(nb, xi_now, T[k], S[k], *args)
            br = nb
        out[k] = martensite_fraction(br, st_, xh, T[k], S[k], *args)
    return out


def through_interface(T, S, m, xi_init, rule, reversal):
    stack = new_stack()
    rec, depth = initial_record(rule, xi_init, T[0], reversal)
    out = np.empty((T.size, 3))
    direction = 0
    for k in range(T.size):
        if k + 1 < T.size:
            direction = drive_direction(rec, T[k + 1] - T[k], S[k + 1] - S[k], m)
        rec, depth = update_memory(rec, stack, depth, T[k], S[k], direction, m)
        out[k] = xi_on_branch(rec, T[k], S[k], m)
    return out


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([(AUTHORS2020, 0.0), (DEADBAND, 0.5),
                                                   (DEADBAND, 2.0)]),
       st.sampled_from([0.05, 0.7, 4.0]), st.booleans(), st.sampled_from([1.0, 0.6, 0.0]))
def test_legacy_rules_reproduce_kinetics_py_to_the_bit(seed, rule, step, stress, xi_init):
    rng = np.random.default_rng(seed)
    n = 300
    T = np.clip(80.0 + np.cumsum(rng.normal(0.0, step, n)), 30.0, 150.0)
    T[rng.integers(0, n, 20)] = T[rng.integers(0, n, 20)]  # some exact holds (dT = 0)
    S = np.clip(100e6 + np.cumsum(rng.normal(0.0, 8e6, n)), 0.0, 300e6) if stress \
        else np.zeros(n)
    code, reversal = rule
    expected = today(T, S, PAPER, xi_init, reversal)
    got = through_interface(T, S, PAPER, xi_init, code, reversal)
    assert np.array_equal(got, expected)
    name = "authors2020" if code == AUTHORS2020 else "deadband"
    assert np.array_equal(xi_history(T, S, PAPER, xi_init, rule=name, reversal_C=reversal).xi,
                          expected[:, 0])


@st.composite
def first_order_cases(draw):
    m = draw(st.sampled_from([PAPER, kinetics_material(60.0, 95.0, 80.0, 50.0, 8e6, 12e6)]))
    sigma = draw(st.floats(0.0, 150e6))
    shift = sigma / m.c_A_Pa_per_C
    T_r = draw(st.floats(m.M_F0_C - 5.0 + shift, m.A_F0_C + 5.0 + shift))
    return m, sigma, T_r


@settings(max_examples=80, deadline=None)
@given(first_order_cases())
def test_first_order_reversal_curves_are_the_papers_scaled_curves(case):
    """From full martensite heat to T_r then cool: xi = xi_A0 + (1 - xi_A0) g_M with xi_A0
    re-solved through the reversal point (Eq. 10b; = xi_r when T_r is above M_S). From full
    austenite cool to T_r then heat: xi = xi_M0 g_A (Eq. 9b)."""
    m, sigma, T_r = case
    args = kinetics_args(m)
    lo, hi = m.M_F0_C - 20.0, m.A_F0_C + 20.0 + sigma / min(m.c_A_Pa_per_C, m.c_M_Pa_per_C)
    for start, xi0, direction in ((lo, 1.0, COOLING), (hi, 0.0, HEATING)):
        T = np.concatenate([np.linspace(start, T_r, 200), np.linspace(T_r, start, 201)[1:]])
        S = np.full(T.size, sigma)
        xi = xi_history(T, S, m, xi_init=xi0).xi
        major = HEATING if direction == COOLING else COOLING
        for k in range(200):  # the major curve
            assert xi[k] == pytest.approx(martensite_fraction(major, xi0, xi0, T[k], sigma,
                                                              *args)[0], abs=1e-15)
        xi_r = xi[199]
        s0 = branch_start(direction, xi_r, T_r, sigma, *args)
        paper = [martensite_fraction(direction, s0, xi_r, t, sigma, *args)[0] for t in T[199:]]
        assert np.max(np.abs(xi[199:] - paper)) <= 1e-12
        if T_r >= m.M_S0_C + sigma / m.c_M_Pa_per_C and direction == COOLING:
            assert s0 == pytest.approx(xi_r, abs=1e-15)  # the paper's xi_A0: the last xi


def test_on_a_major_curve_the_first_motion_follows_it():
    """xi_init = 1 at 23 degC is on the major heating curve, xi_init = 0 at 130 degC on the
    major cooling curve: nothing is assumed beyond that."""
    T = np.linspace(23.0, 130.0, 500)
    up = xi_history(T, np.zeros(500), PAPER, xi_init=1.0).xi
    down = xi_history(T[::-1], np.zeros(500), PAPER, xi_init=0.0).xi
    for k in range(500):
        gM, gA = major_loop(T[k], 0.0, PAPER)
        assert up[k] == pytest.approx(gA, abs=1e-15)
        assert down[::-1][k] == pytest.approx(gM, abs=1e-15)
