"""The oracle's return-point-memory operator (``tests/oracle/memory.py``) against the package's.

Two readings of docs/hysteresis.md written apart: the oracle's (a list of reversal points,
driven at events along an exact trajectory) and ``smafinger.model.hysteresis_reference``
(the pure-Python reference the compiled operator is tested against, bit for bit). Driven
over the same sampled histories, one monotone interval after another, they give the same xi.
"""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from oracle.memory import Memory
from oracle.material import Transformation

from smafinger.model.hysteresis import kinetics_material
from smafinger.model.hysteresis_reference import HysteresisOperator

PAPER = (75.0, 110.0, 85.0, 60.0, 10.3e6)  # Table II: A_S0, A_F0, M_S0, M_F0 [degC], c_A = c_M [Pa/degC]
#: the two find a partial start's reversal point R by different root finders (brentq, bisection):
#: measured at most 5.2e-15 over 1,000 histories (41 % of them bit-identical)
XI_TOL = 1e-12


@st.composite
def materials(draw):
    if draw(st.booleans()):
        return PAPER
    A_S0 = draw(st.floats(40.0, 100.0))
    A_F0 = A_S0 + draw(st.floats(5.0, 40.0))
    M_F0 = A_S0 - draw(st.floats(0.5, 40.0))
    M_S0 = M_F0 + draw(st.floats(3.0, min(40.0, A_F0 - M_F0 - 0.1)))
    return A_S0, A_F0, M_S0, M_F0, draw(st.floats(5e6, 20e6))


@st.composite
def histories(draw):
    """(material, T, sigma, xi_init): random walks or ramps through both bands, with or without stress."""
    A_S0, A_F0, M_S0, M_F0, c = mat = draw(materials())
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    s_max = 150e6
    lo, hi = M_F0 - 10.0, A_F0 + 10.0 + s_max / c
    n = draw(st.integers(2, 300))
    if draw(st.booleans()):
        T = rng.uniform(lo, hi) + np.cumsum(rng.normal(0.0, draw(st.sampled_from([0.05, 0.5, 3.0])), n))
    else:
        turns = rng.uniform(lo, hi, draw(st.integers(2, 12)))
        T = np.concatenate([np.linspace(a, b, rng.integers(1, 40), endpoint=False)
                            for a, b in zip(turns[:-1], turns[1:])] + [turns[-1:]])
    T = np.clip(T, lo, hi)
    if draw(st.booleans()):
        sigma = np.clip(rng.uniform(0, s_max) + np.cumsum(rng.normal(0.0, s_max / 30, T.size)), 0.0, s_max)
    else:
        sigma = np.full(T.size, rng.uniform(0, s_max))
    return mat, T, sigma, draw(st.sampled_from([0.0, 1.0, 0.37, 0.9]))


def oracle_xi(mat, T, sigma, xi_init) -> tuple[np.ndarray, int]:
    """xi at every sample: at each, commit and take the direction of the next interval's tau."""
    A_S0, A_F0, M_S0, M_F0, c = mat
    m = Transformation(A_S0, A_F0, M_S0, M_F0, c, c)
    mem = Memory(xi_init, m)
    out = np.empty(T.size)
    direction = 0
    for k in range(T.size):
        if k + 1 < T.size:
            dtau = (T[k + 1] - T[k]) - (sigma[k + 1] - sigma[k]) / c
            direction = int(dtau > 0.0) - int(dtau < 0.0)
        mem.move(direction, T[k], sigma[k])
        out[k] = mem.held().fraction(T[k], sigma[k], m).xi
    return out, mem.clamps


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(histories())
def test_oracle_memory_equals_the_reference(case):
    mat, T, sigma, xi_init = case
    A_S0, A_F0, M_S0, M_F0, c = mat
    ref = HysteresisOperator(kinetics_material(A_S0, A_F0, M_S0, M_F0, c, c), xi_init)
    expected = ref.run(T, sigma)
    got, clamps = oracle_xi(mat, T, sigma, xi_init)
    assert np.max(np.abs(got - expected)) <= XI_TOL
    assert clamps == ref.clamps


def test_a_nested_history_returns_to_its_branches():
    """Heat into the band, two nested excursions, heat on: past each excursion's start xi rejoins
    the branch it left (return-point memory), exactly as a history without the excursions."""
    m = Transformation(*PAPER[:4], PAPER[4], PAPER[4])
    straight, nested = Memory(1.0, m), Memory(1.0, m)
    straight.move(1, 23.0, 0.0)
    nested.move(1, 23.0, 0.0)
    for T, d in [(90.0, -1), (86.0, 1), (88.0, -1), (87.0, 1)]:  # reversals at 90, 86, 88, 87 degC
        nested.move(d, T, 0.0)
    assert len(nested.points) == 4
    nested.move(1, 89.0, 0.0)  # past 88: the inner loop is wiped out, the branch from 86 resumes
    assert len(nested.points) == 2
    for T in (91.0, 95.0, 100.0):  # past 90: on the major heating curve again
        straight.move(1, T, 0.0)
        nested.move(1, T, 0.0)
        a, b = straight.held().fraction(T, 0.0, m).xi, nested.held().fraction(T, 0.0, m).xi
        assert a == b and 0.0 < a < 1.0
    assert nested.points == [] and nested.branch == straight.branch
