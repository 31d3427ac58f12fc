"""The engine-facing interface: virgin states, within-step behaviour, stack overflow,
direction choice and errors."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from smafinger.model import hysteresis_checks as hc
from smafinger.model.hysteresis import (
    MEMORY, drive_direction, initial_record, kinetics_material, major_loop, max_loop_stress_Pa,
    new_stack, rule_code, update_memory, xi_on_branch,
)
from smafinger.model.hysteresis_drive import xi_history
from smafinger.model.hysteresis_reference import HysteresisOperator

PAPER = kinetics_material(75.0, 110.0, 85.0, 60.0, 10.3e6, 10.3e6)


@settings(max_examples=60, deadline=None)
@given(st.floats(62.0, 108.0), st.floats(0.02, 0.98), st.floats(0.0, 100e6))
def test_a_partial_start_is_a_consistent_history(T0, u, sigma):
    """Inside the loop the wire is taken to have cooled from R on the major heating curve:
    heating past R rejoins the major heating curve, cooling follows R's first-order curve."""
    T0 += sigma / PAPER.c_A_Pa_per_C
    gM, gA = major_loop(T0, sigma, PAPER)
    xi0 = gM + u * (gA - gM)
    for end in (150.0, 20.0):
        T = np.linspace(T0, end, 400)
        r = xi_history(T, np.full(400, sigma), PAPER, xi_init=xi0)
        assert r.xi[0] == xi0 and r.clamps == 0
        assert hc.direction_violations(T, np.full(400, sigma), r.xi, PAPER).size == 0
        gM_end, gA_end = major_loop(end, sigma, PAPER)
        assert r.xi[-1] == pytest.approx(gA_end if end > T0 else gM_end, abs=1e-12)
    # heating: held (flat) until the major heating curve, then on it
    T = np.linspace(T0, 150.0, 400)
    r = xi_history(T, np.full(400, sigma), PAPER, xi_init=xi0)
    on_major = np.array([abs(x - major_loop(t, sigma, PAPER)[1]) <= 1e-12 for t, x in zip(T, r.xi)])
    first = np.argmax(on_major)
    assert np.all(on_major[first:]) and np.all(r.xi[:first] <= xi0)


def test_a_start_outside_the_loop_is_clamped_and_counted():
    r = xi_history(np.linspace(95.0, 100.0, 10), np.zeros(10), PAPER, xi_init=1.0)
    assert r.clamps == 1 and r.xi[0] == major_loop(95.0, 0.0, PAPER)[1]


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.5, 3.0, 8.0]))
def test_within_a_step_two_targets_cost_at_most_L_dtau(seed, step):
    """xi_on_branch continues past one target on the parent branch exactly; past two within
    one sub-step it extrapolates the parent (inside the loop) until the next update corrects
    it: the jump is at most L |dtau| of the step (L: steepest major-curve slope)."""
    rng = np.random.default_rng(seed)
    T = np.clip(85.0 + np.cumsum(rng.normal(0.0, step, 300)), 40.0, 130.0)
    S = np.zeros(300)
    xi0 = major_loop(T[0], 0.0, PAPER)[1]  # on the major heating curve
    r = xi_history(T, S, PAPER, xi_init=xi0)
    ref = HysteresisOperator(PAPER, xi0)
    ref.run(T, S)
    L = math.pi / 2 / min(PAPER.A_F0_C - PAPER.A_S0_C, PAPER.M_S0_C - PAPER.M_F0_C)
    jump = np.abs(r.xi - r.xi_step_end)
    dtau = np.abs(np.diff(T, prepend=T[0]))
    passes = np.array(ref.passes)
    assert np.all(jump[passes <= 1] <= 1e-12)
    assert np.all(jump <= L * dtau + 1e-12)


def test_stack_overflow_merges_the_innermost_loop():
    """Nested loops 90 +- 20, 19, ... 1 degC need about 40 rows; with 4 the innermost loops are
    merged: still continuous, monotone and inside the loop, and once a heating to 130 degC
    has wiped everything out, the same as with room for all."""
    amp = np.arange(20.0, 0.0, -1.0)
    turns = np.concatenate([[23.0], (90.0 + amp * np.resize([1, -1], amp.size)), [130.0, 60.0]])
    T = np.concatenate([np.arange(a, b, 0.01 * np.sign(b - a)) for a, b in
                        zip(turns[:-1], turns[1:])] + [turns[-1:]])
    S = np.zeros(T.size)
    small = xi_history(T, S, PAPER, capacity=4)
    big = xi_history(T, S, PAPER, capacity=64)
    assert small.merges > 0 and big.merges == 0 and big.depth.max() > 4
    assert hc.jump_violations(small.xi, small.xi_step_end).size == 0
    assert hc.direction_violations(T, S, small.xi, PAPER).size == 0
    assert hc.loop_violations(T, S, small.xi, PAPER).size == 0
    first_merge = np.argmax(small.depth < np.minimum(big.depth, 4))
    assert np.array_equal(small.xi[:first_merge], big.xi[:first_merge])
    wiped = np.argmax(T >= 111.0)  # past A_F: both on the major curves from here
    assert np.max(np.abs(small.xi[wiped:] - big.xi[wiped:])) <= 1e-12


@st.composite
def nested_paths(draw):
    """Turning points that mostly nest (each inside the last loop), finely sampled."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    lo, hi = 50.0, 120.0
    turns = [rng.uniform(lo, hi)]
    for _ in range(draw(st.integers(5, 40))):
        if rng.random() < 0.85:
            lo, hi = (turns[-1], hi) if len(turns) % 2 else (lo, turns[-1])
        turns.append(rng.uniform(lo, hi))
    turns.append(draw(st.sampled_from([40.0, 130.0])))
    T = np.concatenate([np.linspace(a, b, max(2, int(abs(b - a) / 0.02)), endpoint=False)
                        for a, b in zip(turns[:-1], turns[1:])] + [turns[-1:]])
    return T, draw(st.integers(4, 5))


@settings(max_examples=250, deadline=None)
@given(nested_paths())
def test_merged_loops_keep_properties_1_to_3(case):
    T, capacity = case
    S = np.zeros(T.size)
    xi0 = major_loop(T[0], 0.0, PAPER)[1]
    r = xi_history(T, S, PAPER, xi_init=xi0, capacity=capacity)
    L = math.pi / 2 / min(PAPER.A_F0_C - PAPER.A_S0_C, PAPER.M_S0_C - PAPER.M_F0_C)
    # continuous: at 0.02 degC per sample no step of xi is steeper than a few major slopes
    assert np.all(np.abs(np.diff(r.xi)) <= 4 * L * np.abs(np.diff(T)) + 1e-12)
    assert hc.direction_violations(T, S, r.xi, PAPER).size == 0
    assert hc.loop_violations(T, S, r.xi, PAPER).size == 0
    assert r.depth.max() <= capacity


def test_the_same_history_gives_the_same_bits():
    rng = np.random.default_rng(5)
    T = 85.0 + np.cumsum(rng.normal(0.0, 1.0, 500))
    S = np.clip(80e6 + np.cumsum(rng.normal(0.0, 5e6, 500)), 0.0, None)
    a, b = xi_history(T, S, PAPER), xi_history(T, S, PAPER)
    assert np.array_equal(a.xi, b.xi) and np.array_equal(a.xi_step_end, b.xi_step_end)


def test_xi_on_branch_derivatives_match_finite_differences():
    stack = new_stack()
    rec, depth = initial_record(MEMORY, 1.0, 23.0, 0.0)
    for T in (23.0, 70.0, 95.0):  # heat to 95 on the major curve, then reverse
        rec, depth = update_memory(rec, stack, depth, T, 20e6, 1, PAPER)
    rec, depth = update_memory(rec, stack, depth, 95.0, 20e6, -1, PAPER)
    for T, s in ((80.0, 20e6), (78.0, 10e6)):
        xi, dT, ds = xi_on_branch(rec, T, s, PAPER)
        h, hs = 1e-5, 1e2
        assert dT == pytest.approx((xi_on_branch(rec, T - h, s, PAPER)[0]
                                    - xi_on_branch(rec, T + h, s, PAPER)[0]) / (-2 * h), rel=1e-6)
        assert ds == pytest.approx((xi_on_branch(rec, T, s + hs, PAPER)[0]
                                    - xi_on_branch(rec, T, s - hs, PAPER)[0]) / (2 * hs), rel=1e-6)
        assert dT < 0.0 < ds  # cooling branch inside the band: xi rises as tau_M falls


def test_drive_direction():
    rec, _ = initial_record(MEMORY, 1.0, 23.0, 0.0)
    m = kinetics_material(75.0, 110.0, 85.0, 60.0, 8e6, 15e6)
    assert drive_direction(rec, 1.0, 0.0, m) == 1 and drive_direction(rec, -1.0, 0.0, m) == -1
    assert drive_direction(rec, 0.0, 0.0, m) == 0
    assert drive_direction(rec, 1.0, 10e6, m) == 0  # tau_A falls, tau_M rises: neither
    assert drive_direction(rec, 1.0, 20e6, PAPER) == -1  # c_A = c_M: the sign of dtau/dt
    legacy, _ = initial_record(rule_code("authors2020"), 1.0, 23.0, 0.0)
    assert drive_direction(legacy, 1.0, 1e9, PAPER) == 1  # the authors: the sign of dT/dt


@pytest.mark.parametrize("kwargs, message", [
    ({"A_F0_C": 70.0}, "A_F0_C = 70.0 must exceed A_S0_C = 75.0"),
    ({"M_F0_C": 86.0}, "M_S0_C = 85.0 must exceed M_F0_C = 86.0"),
    ({"M_F0_C": 76.0, "M_S0_C": 90.0}, "A_S0_C = 75.0 must exceed M_F0_C = 76.0"),
    ({"M_S0_C": 111.0}, "A_F0_C = 110.0 must exceed M_S0_C = 111.0"),
    ({"c_M_Pa_per_C": 0.0}, "c_M_Pa_per_C = 0.0 must be positive"),
    ({"A_S0_C": float("nan")}, "A_S0_C = nan is not a finite number"),
])
def test_bad_material_names_the_field_and_value(kwargs, message):
    values = dict(zip(PAPER._fields, PAPER)) | kwargs
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        kinetics_material(**values)


def test_bad_arguments_name_the_field_and_value():
    with pytest.raises(ValueError, match="kinetics rule = 'memroy'"):
        rule_code("memroy")
    with pytest.raises(ValueError, match="capacity = 2 must be an integer >= 4"):
        new_stack(2)
    with pytest.raises(ValueError, match="xi_init = 1.5 is not in"):
        xi_history([1.0, 2.0], [0.0, 0.0], PAPER, xi_init=1.5)
    with pytest.raises(ValueError, match="sigma has a non-finite sample at index 1"):
        xi_history([1.0, 2.0], [0.0, np.inf], PAPER)
    with pytest.raises(ValueError, match="reversal_C = 0.0 must be a finite number > 0"):
        xi_history([1.0, 2.0], [0.0, 0.0], PAPER, rule="deadband", reversal_C=0.0)


def test_max_loop_stress():
    assert max_loop_stress_Pa(PAPER) == math.inf
    m = kinetics_material(75.0, 110.0, 85.0, 60.0, 15e6, 8e6)
    s = max_loop_stress_Pa(m)
    for T in np.linspace(40.0, 160.0, 241):  # not empty below s
        gM, gA = major_loop(T, 0.999 * s, m)
        assert gM <= gA
    T = 59.5 + 1.1 * s / 8e6  # above s: tau_M = 59.5 (g_M = 1) while tau_A = 76 (g_A < 1)
    gM, gA = major_loop(T, 1.1 * s, m)
    assert gM == 1.0 > gA


def test_the_documented_entry_points_name_what_they_refuse():
    """Found by an API fuzz: a parameter set given as the material reached numba's typing (pages
    of compiler text), an infinite dead band never transformed, and an int beyond any float was
    an OverflowError where the docstring promised a ValueError naming the field."""
    from smafinger.model.hysteresis import kinetics_material, material_from_parameters
    from smafinger.model.hysteresis_drive import xi_history
    from smafinger.parameters import get

    T, sigma = np.linspace(20.0, 120.0, 50), np.zeros(50)
    with pytest.raises(TypeError, match="material = JointParameters: give a KineticsMaterial"):
        xi_history(T, sigma, get("paper2010"))
    m = material_from_parameters(get("paper2010"))
    with pytest.raises(ValueError, match="reversal_C = inf must be a finite number > 0"):
        xi_history(T, sigma, m, rule="deadband", reversal_C=float("inf"))
    assert xi_history(T, sigma, m, rule="deadband").xi[-1] == 0.0  # heated through the band: austenite
    with pytest.raises(ValueError, match="A_S0_C = inf is not a finite number"):
        kinetics_material(10 ** 400, 110.0, 85.0, 60.0, 1e7, 1e7)
