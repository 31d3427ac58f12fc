"""Properties 1-5 of the hysteresis operator (docs/hysteresis.md), on random histories of
temperature and stress, for the paper's material and random valid ones (c_A = c_M and not).
Each property's checker is also shown to catch today's rules (``authors2020``, ``deadband``).
"""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from smafinger.model import hysteresis_checks as hc
from smafinger.model.hysteresis import kinetics_material, major_loop, max_loop_stress_Pa
from smafinger.model.hysteresis_drive import xi_history
from smafinger.model.hysteresis_reference import HysteresisOperator

PAPER = kinetics_material(75.0, 110.0, 85.0, 60.0, 10.3e6, 10.3e6)  # Table II
SETTINGS = settings(max_examples=120, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


@st.composite
def materials(draw):
    kind = draw(st.sampled_from(["paper", "equal c", "unequal c"]))
    if kind == "paper":
        return PAPER
    A_S0 = draw(st.floats(40.0, 100.0))
    A_F0 = A_S0 + draw(st.floats(5.0, 40.0))
    M_F0 = A_S0 - draw(st.floats(0.5, 40.0))
    M_S0 = M_F0 + draw(st.floats(3.0, min(40.0, A_F0 - M_F0 - 0.1)))
    c_A = draw(st.floats(5e6, 20e6))
    c_M = c_A if kind == "equal c" else draw(st.floats(5e6, 20e6))
    return kinetics_material(A_S0, A_F0, M_S0, M_F0, c_A, c_M)


def stress_cap(m):
    return min(300e6, 0.9 * max_loop_stress_Pa(m))


def temperature_range(m, s_max):
    """T that sweeps tau over both bands at any stress up to s_max."""
    c = min(m.c_A_Pa_per_C, m.c_M_Pa_per_C)
    return m.M_F0_C - 10.0, m.A_F0_C + 10.0 + s_max / c


def start_inside(m, T0, s0, u):
    """xi_init on the major loop at the start: g_M + u (g_A - g_M)."""
    gM, gA = major_loop(T0, s0, m)
    return gM + u * (gA - gM)


@st.composite
def histories(draw, m):
    """(T, sigma, xi_init): random walks, ramps with reversals, ripple on ramps, with holds."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    s_max = stress_cap(m)
    lo, hi = temperature_range(m, s_max)
    kind = draw(st.sampled_from(["walk", "ramps", "ripple"]))
    n = draw(st.integers(2, 300))
    if kind == "walk":
        T = rng.uniform(lo, hi) + np.cumsum(rng.normal(0.0, draw(st.sampled_from([0.05, 0.5, 3.0])), n))
    elif kind == "ramps":
        turns = rng.uniform(lo, hi, draw(st.integers(2, 12)))
        T = np.concatenate([np.linspace(a, b, rng.integers(1, 40), endpoint=False)
                            for a, b in zip(turns[:-1], turns[1:])] + [turns[-1:]])
    else:
        t = np.linspace(0.0, 1.0, n)
        a, b = rng.uniform(lo, hi, 2)
        T = a + (b - a) * t + draw(st.floats(0.01, 1.0)) * np.sin(
            2 * np.pi * draw(st.floats(1.0, 100.0)) * t + rng.uniform(0, 2 * np.pi))
    T = np.clip(T, lo, hi)
    stress = draw(st.sampled_from(["none", "constant", "walk"]))
    if stress == "walk":
        sigma = rng.uniform(0, s_max) + np.cumsum(rng.normal(0.0, s_max / 30, T.size))
    else:
        sigma = np.full(T.size, rng.uniform(0, s_max) if stress == "constant" else 0.0)
    sigma = np.clip(sigma, 0.0, s_max)
    if draw(st.booleans()):  # holds: repeat random samples
        reps = rng.choice([1, 1, 1, 2, 5], T.size)
        T, sigma = np.repeat(T, reps), np.repeat(sigma, reps)
    u = draw(st.sampled_from([0.0, 1.0, 0.37]))
    return T, sigma, start_inside(m, T[0], sigma[0], u)


def material_and_history():
    return materials().flatmap(lambda m: histories(m).map(lambda h: (m, *h)))


def polyline(*points, n=40):
    """Samples along straight segments between (T, sigma) points, n per segment."""
    T, S = [], []
    for (a, sa), (b, sb) in zip(points[:-1], points[1:]):
        T += list(np.linspace(a, b, n, endpoint=False))
        S += list(np.linspace(sa, sb, n, endpoint=False))
    return np.array(T + [points[-1][0]]), np.array(S + [points[-1][1]])


# a history of today's rules' troubles: heat under 150 MPa into the heating band, then let the
# stress go while the wire cools by 1 degC (tau rises past A_F), then heat again
STRESS_DROP = polyline((23.0, 150e6), (115.0, 150e6), (114.0, 0.0), (115.0, 0.0))
# +-0.3 degC ripple (100 periods) on a wire heated to 95 degC (the reviewer's case)
RIPPLE_95 = (np.concatenate([np.linspace(23.0, 95.0, 200),
                             95.0 + 0.3 * np.sin(2 * np.pi * 100 * np.linspace(0, 1, 4001))]),
             np.zeros(4201))


# ---- the numba operator, driven as the engine drives it, against the pure-Python reference --
@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(material_and_history())
def test_numba_operator_equals_the_reference(case):
    m, T, sigma, xi0 = case
    r = xi_history(T, sigma, m, xi_init=xi0)
    ref = HysteresisOperator(m, xi0)
    assert np.array_equal(r.xi, ref.run(T, sigma))  # the same operations: to the bit
    assert r.clamps == ref.clamps


@st.composite
def unequal_c_stress_walks(draw):
    """c_A != c_M with T and sigma both wandering: the two taus move apart and cross."""
    m = draw(materials().filter(lambda m: m.c_A_Pa_per_C != m.c_M_Pa_per_C))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    s_max = stress_cap(m)
    lo, hi = temperature_range(m, s_max)
    n = draw(st.integers(10, 300))
    dT = rng.normal(0.0, draw(st.sampled_from([0.3, 2.0])), n)
    if draw(st.booleans()):  # stress steps independent of the temperature steps
        ds = rng.normal(0.0, s_max / 20, n)
    else:  # dsigma/dT between c_A and c_M, often: one tau rises while the other falls
        c = rng.uniform(min(m.c_A_Pa_per_C, m.c_M_Pa_per_C), max(m.c_A_Pa_per_C, m.c_M_Pa_per_C), n)
        ds = dT * c * rng.choice([1.0, 1.0, 0.5, -1.0], n)
    T = np.clip(rng.uniform(lo, hi) + np.cumsum(dT), lo, hi)
    sigma = np.clip(rng.uniform(0, s_max) + np.cumsum(ds), 0.0, s_max)
    return m, T, sigma, start_inside(m, T[0], sigma[0], draw(st.sampled_from([0.0, 1.0, 0.37])))


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(unequal_c_stress_walks())
def test_unequal_c_properties_and_reference(case):
    m, T, sigma, xi0 = case
    r = xi_history(T, sigma, m, xi_init=xi0)
    ref = HysteresisOperator(m, xi0)
    assert np.array_equal(r.xi, ref.run(T, sigma))
    assert max(ref.pop_gaps, default=0.0) <= 1e-12
    assert max(ref.flat_gaps, default=0.0) <= 1e-12 and not ref.unreachable
    assert all(ref.passes[k] >= 2 for k in hc.jump_violations(r.xi, r.xi_step_end))
    assert hc.direction_violations(T, sigma, r.xi, m).size == 0
    assert hc.loop_violations(T, sigma, r.xi, m).size == 0


# ---- property 1: continuous, in [0, 1] ------------------------------------------------------
@SETTINGS
@given(material_and_history())
def test_p1_continuous_and_in_range(case):
    m, T, sigma, xi0 = case
    r = xi_history(T, sigma, m, xi_init=xi0)
    ref = HysteresisOperator(m, xi0)
    x = ref.run(T, sigma)
    assert hc.range_violations(r.xi).size == 0 and hc.range_violations(x).size == 0
    # the exact operator: the branch resumed at a wiped-out target meets the one that
    # reached it there; a flat branch joins points of equal xi
    assert max(ref.pop_gaps, default=0.0) <= 1e-12
    assert max(ref.flat_gaps, default=0.0) <= 1e-12 and not ref.unreachable
    # the engine's way: an update (reversal, wipe-out, clamp) never moves xi, except after
    # an interval that reached two or more targets (the one-level parent, within-step)
    jumps = hc.jump_violations(r.xi, r.xi_step_end)
    assert all(ref.passes[k] >= 2 for k in jumps)


def test_p1_catches_today_rules_and_the_papers_text():
    T, S = STRESS_DROP
    for rule in ("authors2020", "deadband"):
        r = xi_history(T, S, PAPER, rule=rule)
        assert hc.jump_violations(r.xi, r.xi_step_end).size > 0, rule
    r = xi_history(T, S, PAPER)
    assert hc.jump_violations(r.xi, r.xi_step_end).size == 0
    # the paper's text (xi_A0 = the last xi of the heating phase) jumps at a reversal inside
    # the cooling band: heated to 80 degC, xi = g_A(80) but the cooling curve gives more
    from smafinger.model.kinetics import COOLING, martensite_fraction
    xi_r = major_loop(80.0, 0.0, PAPER)[1]
    after = martensite_fraction(COOLING, xi_r, 0.0, 80.0, 0.0, 75.0, 110.0, 10.3e6, 85.0, 60.0,
                                10.3e6)[0]
    assert hc.jump_violations([after], [xi_r]).size == 1


# ---- property 2: direction and bands ---------------------------------------------------------
@SETTINGS
@given(material_and_history())
def test_p2_moves_only_with_its_driving_tau_inside_its_band(case):
    m, T, sigma, xi0 = case
    r = xi_history(T, sigma, m, xi_init=xi0)
    assert hc.direction_violations(T, sigma, r.xi, m).size == 0


def test_p2_holds_while_neither_transformation_is_driven():
    """c_M > c_A: T up 1 degC while sigma rises 10 MPa, so tau_A falls and tau_M rises."""
    m = kinetics_material(75.0, 110.0, 85.0, 60.0, 8e6, 15e6)
    T, S = polyline((100.0, 0.0), (70.0, 0.0), (71.0, 10e6), (72.0, 20e6))
    r = xi_history(T, S, m)
    assert np.all(np.diff(r.xi[80:]) == 0.0) and hc.direction_violations(T, S, r.xi, m).size == 0
    # and back on the cooling branch once tau_M falls past where it turned
    T2, S2 = polyline((100.0, 0.0), (70.0, 0.0), (71.0, 10e6), (69.0, 10e6))
    x = xi_history(T2, S2, m).xi
    assert x[80] == r.xi[80] and x[-1] > x[80]
    assert x[-1] == pytest.approx(xi_history(*polyline((100.0, 0.0), (70.0, 0.0), (70.0, 10e6),
                                                       (69.0, 10e6)), m).xi[-1], abs=1e-12)


def test_p2_catches_today_rules():
    # dead band: after a reversal xi keeps falling for 0.5 degC of cooling
    T, S = polyline((23.0, 0.0), (95.0, 0.0), (94.6, 0.0))
    assert hc.direction_violations(T, S, xi_history(T, S, PAPER, rule="deadband").xi,
                                   PAPER).size > 0
    # both: T rises but the stress rises faster, so tau falls (above M_S): xi must hold
    T, S = polyline((23.0, 0.0), (95.0, 0.0), (96.0, 50e6))
    for rule in ("authors2020", "deadband"):
        assert hc.direction_violations(T, S, xi_history(T, S, PAPER, rule=rule).xi,
                                       PAPER).size > 0, rule
    assert hc.direction_violations(T, S, xi_history(T, S, PAPER).xi, PAPER).size == 0


# ---- property 3: inside the major loop -------------------------------------------------------
@SETTINGS
@given(material_and_history())
def test_p3_inside_the_major_loop(case):
    m, T, sigma, xi0 = case
    r = xi_history(T, sigma, m, xi_init=xi0)
    assert hc.loop_violations(T, sigma, r.xi, m).size == 0
    if m.c_A_Pa_per_C == m.c_M_Pa_per_C:
        # the branches themselves stay inside: the clamp never acted beyond rounding
        assert r.clamps == 0


def test_p3_catches_today_rules():
    T, S = RIPPLE_95  # the dead band ratchets xi to 1 where the loop allows 0 .. 0.389
    r = xi_history(T, S, PAPER, rule="deadband")
    assert r.xi[-1] == 1.0 and major_loop(95.0, 0.0, PAPER)[1] < 0.39
    assert hc.loop_violations(T, S, r.xi, PAPER).size > 0
    T, S = STRESS_DROP  # tau rises past A_F on the "cooling" branch (dT < 0): xi stays
    assert hc.loop_violations(T, S, xi_history(T, S, PAPER, rule="authors2020").xi,
                              PAPER).size > 0


# ---- property 4: return-point memory ---------------------------------------------------------
def state_before(m, T, sigma, xi0, k):
    """The reference operator after samples 0 .. k-1 (directions toward the next sample)."""
    op = HysteresisOperator(m, xi0)
    for j in range(k):
        op.step(T[j], sigma[j], op.direction(T[j + 1] - T[j], sigma[j + 1] - sigma[j]))
    return op


def excursion_room(m, op, T_k, sigma_k):
    """(d, T_far): the branch arriving at sample k goes in d; an excursion at sigma_k may
    go from T_k back toward T_far (exclusive) without reaching the previous reversal point."""
    d = op.branch.direction
    if not op.points:
        return d, -math.inf * d
    c = m.c_M_Pa_per_C if d > 0 else m.c_A_Pa_per_C
    return d, op.points[-1].tau(-d) + sigma_k / c


@SETTINGS
@given(material_and_history(), st.data())
def test_p4_return_point_memory(case, data):
    m, T, sigma, xi0 = case
    assume(T.size >= 3)
    k = data.draw(st.integers(1, T.size - 2))
    op = state_before(m, T, sigma, xi0, k)
    assume(op.branch is not None)
    d, T_far = excursion_room(m, op, T[k], sigma[k])
    here = op._point(T[k], sigma[k], 0.0)
    assume(op._reached(d, here.tau(d), op.extreme.tau(d)))  # not holding behind an extreme
    lo, hi = temperature_range(m, stress_cap(m))
    far = max(T_far, lo) if d > 0 else min(T_far, hi)
    assume((T[k] - far) * d > 1e-6)
    u = np.array(data.draw(st.lists(st.floats(0.0, 1.0), min_size=1, max_size=30)))
    u = np.minimum(u, 1.0 - 1e-9)  # strictly before the previous reversal point
    E = np.concatenate([T[k] + u * (far - T[k]), [T[k]]])  # wander back, return to sample k
    # a turn whose tau rounds to sample k's is a loop of zero width: dropped at birth, its branch
    # re-anchored at the point (docs/hysteresis.md), so equal to rounding only (the next test;
    # CI's random search found one: 2 ulps of T below 105.17 degC, the same tau at 171 MPa)
    c = m.c_A_Pa_per_C if d > 0 else m.c_M_Pa_per_C  # the tau the branch back to sample k is aimed in
    assume(np.all((E[:-1] - sigma[k] / c) != (T[k] - sigma[k] / c)))
    T2 = np.concatenate([T[:k + 1], E, T[k + 1:]])
    S2 = np.concatenate([sigma[:k + 1], np.full(E.size, sigma[k]), sigma[k + 1:]])
    base = xi_history(T, sigma, m, xi_init=xi0).xi
    with_excursion = xi_history(T2, S2, m, xi_init=xi0).xi
    # after the excursion the history continues as if it had not happened, to the bit
    assert np.array_equal(with_excursion[k + 1 + E.size:], base[k + 1:])
    assert np.array_equal(with_excursion[:k + 1], base[:k + 1])


def test_p4_a_loop_of_zero_width_rejoins_to_rounding():
    """Heating at 171 MPa, a turn about one ulp of T back whose tau rounds to the same value,
    then on: the loop is dropped at birth and its branch re-anchored at the point, so the
    continuation equals the history without it to rounding (the case CI's random search of the
    test above found)."""
    sigma, T_k, T_back = 171284036.6687411, 105.17046332405262, 105.1704633240526
    c = PAPER.c_A_Pa_per_C
    assert T_back < T_k and T_back - sigma / c == T_k - sigma / c  # a loop of zero width in tau
    T = np.concatenate([np.linspace(70.0, T_k, 36), np.linspace(T_k, 127.0, 22)[1:]])
    k = 35
    T2 = np.concatenate([T[:k + 1], [T_back, T_k], T[k + 1:]])
    base = xi_history(T, np.full(T.size, sigma), PAPER, xi_init=1.0).xi
    with_turn = xi_history(T2, np.full(T2.size, sigma), PAPER, xi_init=1.0).xi
    assert np.ptp(base[k + 1:]) > 0.1  # transforming after the turn
    assert np.array_equal(with_turn[:k + 1], base[:k + 1])
    assert np.max(np.abs(with_turn[k + 3:] - base[k + 1:])) <= 4 * np.finfo(float).eps


def test_p4_exact_when_the_excursion_starts_at_a_reversal():
    """The base reverses at 82 degC (inside both bands); an excursion 82 -> 72 -> 82 inserted
    there changes no bit of what follows."""
    T, S = polyline((23.0, 0.0), (82.0, 0.0), (62.0, 0.0))
    T2, S2 = polyline((23.0, 0.0), (82.0, 0.0), (72.0, 0.0), (82.0, 0.0), (62.0, 0.0))
    a = xi_history(T, S, PAPER).xi
    b = xi_history(T2, S2, PAPER).xi
    assert np.array_equal(a[41:], b[121:]) and np.ptp(a[41:]) > 0.05


def test_p4_catches_today_rules():
    """Heat to 95 degC, wander down to 80 and back, heat on to 100."""
    T, S = polyline((23.0, 0.0), (95.0, 0.0), (100.0, 0.0))
    T2, S2 = polyline((23.0, 0.0), (95.0, 0.0), (80.0, 0.0), (95.0, 0.0), (100.0, 0.0))
    for rule, expect_same in (("memory", True), ("authors2020", False), ("deadband", False)):
        a = xi_history(T, S, PAPER, rule=rule).xi[-41:]
        b = xi_history(T2, S2, PAPER, rule=rule).xi[-41:]
        assert (np.max(np.abs(a - b)) <= 1e-12) == expect_same, rule


# ---- property 5: ripple ----------------------------------------------------------------------
@st.composite
def ripple_cases(draw):
    m = draw(materials())
    s_max = stress_cap(m)
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    s0 = rng.uniform(0, s_max)
    s1 = float(np.clip(s0 + rng.uniform(-0.2, 0.2) * s_max, 0.0, s_max))
    c = min(m.c_A_Pa_per_C, m.c_M_Pa_per_C)
    lo, hi = m.M_F0_C - 10.0 + s0 / c, m.A_F0_C + 10.0 + s0 / c
    a, b = rng.uniform(lo, hi, 2)
    assume(abs(b - a) > 2 * abs(s1 - s0) / c + 1.0)  # both taus monotone along the ramp
    d = draw(st.sampled_from([0.01, 0.1, 0.3, 1.0]))
    # the start (xi = 1 heating, 0 cooling) on the major loop for the ramp and the rippled T alike: a
    # start outside the loop is clamped at the first sample (tested on its own), whatever P5 says
    if b > a:
        assume(a + d < m.A_S0_C + s0 / m.c_A_Pa_per_C)
    else:
        assume(a - d > m.M_S0_C + s0 / m.c_M_Pa_per_C)
    n = draw(st.integers(50, 3000))
    periods = draw(st.floats(2.0, 500.0))  # the "PWM frequency"
    t = np.linspace(0.0, 1.0, n)
    ramp = a + (b - a) * t
    T = ramp + d * np.sin(2 * np.pi * periods * t + rng.uniform(0, 2 * np.pi))
    S = s0 + (s1 - s0) * t
    return m, ramp, T, S, d, (1.0 if b > a else 0.0)


@settings(max_examples=150, deadline=None)
@given(ripple_cases())
def test_p5_ripple_moves_xi_by_at_most_C_d(case):
    m, ramp, T, S, d, xi0 = case
    smooth = xi_history(ramp, S, m, xi_init=xi0).xi
    rippled = xi_history(T, S, m, xi_init=xi0).xi
    # at every sample, however many periods (no accumulation) and whatever their frequency
    assert np.max(np.abs(rippled - smooth)) <= hc.ripple_gain(m) * d


def test_p5_catches_today_rules():
    T, S = RIPPLE_95
    C_d = hc.ripple_gain(PAPER) * 0.3
    smooth = xi_history(np.where(np.arange(T.size) < 200, T, 95.0), S, PAPER).xi  # held at 95
    for rule in ("authors2020", "deadband"):
        r = xi_history(T, S, PAPER, rule=rule).xi
        assert np.max(np.abs(r - smooth)) > 2 * C_d, rule
    assert np.max(np.abs(xi_history(T, S, PAPER).xi - smooth)) <= C_d
    # authors2020: each ripple period moves xi by a fixed amount, so the result depends on
    # the number of periods (the PWM frequency), not only on the amplitude
    T10 = np.concatenate([T[:200], 95.0 + 0.3 * np.sin(2 * np.pi * 10 * np.linspace(0, 1, 4001))])
    a10 = xi_history(T10, S, PAPER, rule="authors2020").xi[-1]
    a100 = xi_history(T, S, PAPER, rule="authors2020").xi[-1]
    assert abs(a10 - a100) > C_d


@SETTINGS
@given(material_and_history(), st.integers(2, 6))
def test_refined_sampling_gives_the_same_xi(case, refine):
    """Rate independence: sampling the same piecewise-linear path finer changes nothing at
    the original samples (so nothing depends on the step size but the path)."""
    m, T, sigma, xi0 = case
    t = np.arange(T.size)
    tf = np.linspace(0, T.size - 1, (T.size - 1) * refine + 1)
    fine = xi_history(np.interp(tf, t, T), np.interp(tf, t, sigma), m, xi_init=xi0).xi
    coarse = xi_history(T, sigma, m, xi_init=xi0).xi
    assert np.max(np.abs(fine[::refine] - coarse)) <= 1e-12
