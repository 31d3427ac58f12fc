"""The authors' martensite-fraction functions as their Simulink model calls them
(model/hysteresis_authors.py): a branch per call from the sign of dT/dt, start values re-solved
at every call with the raw cosines, the last output held while dT/dt = 0."""

import math

import pytest

from smafinger.engine.run import kernel_args, make_spec
from smafinger.model.hysteresis import xi_on_branch
from smafinger.model.hysteresis_authors import call_record, committed_call, globals_of, initial_calls_record

SIGMA = 18e6  #: a wire stress [Pa]


@pytest.fixture(scope="module")
def wire():
    return kernel_args(make_spec("authors2020", "independent", "0:-25:upper", t_end_s=1.0,
                                 method="authors-ode4"))["model"].wires[0]


def _call(rec, dT_dt, T, sigma, m):
    """One call: (E, record after it)."""
    rec = call_record(rec, dT_dt)
    E = xi_on_branch(rec, T, sigma, m)[0]
    return E, committed_call(rec, T, sigma, E, m)


def _bands(m, sigma):
    """(Ua, La, Um, Lm) at stress sigma: the transformation bands shifted by sigma / c."""
    return (m.A_S0_C + sigma / m.c_A_Pa_per_C, m.A_F0_C + sigma / m.c_A_Pa_per_C,
            m.M_F0_C + sigma / m.c_M_Pa_per_C, m.M_S0_C + sigma / m.c_M_Pa_per_C)


def test_a_reversal_keeps_the_point(wire):
    """Heating into the A band, then a cooling call and a heating call at the same point: each
    re-solved start makes its branch pass through the last output."""
    Ua, La, _, _ = _bands(wire, SIGMA)
    rec = initial_calls_record(1.0)
    E_heat, rec = _call(rec, +1.0, 0.5 * (Ua + La), SIGMA, wire)
    assert 0.0 < E_heat < 1.0
    E_cool, rec = _call(rec, -1.0, 0.5 * (Ua + La), SIGMA, wire)
    E_back, rec = _call(rec, +1.0, 0.5 * (Ua + La), SIGMA, wire)
    assert E_cool == pytest.approx(E_heat, rel=1e-12)
    assert E_back == pytest.approx(E_heat, rel=1e-12)


def test_a_cooling_call_above_la_keeps_the_heating_branch_through_its_point(wire):
    """Above La a cooling call re-solves Es with the raw cosine kA (1 + kA small, not the clamped
    curve's 0): a heating call at a higher stress, where T is back below La, continues the branch
    through that point, E (1 + kA') / (1 + kA), instead of restarting it from full martensite."""
    a = math.pi / (wire.A_F0_C - wire.A_S0_C)
    rec = initial_calls_record(0.16)._replace(parent_slope=0.16)  # Ef = 0.16, as a heating call leaves it
    _, La, _, _ = _bands(wire, SIGMA)
    T = La + 0.02
    E, rec = _call(rec, -1.0, T, SIGMA, wire)  # above Lm: E = Ef
    assert E == 0.16
    sigma2 = SIGMA + 0.5 * wire.c_A_Pa_per_C * 0.1  # La 0.05 degC higher: T is below it again
    E2, _ = _call(rec, +1.0, T, sigma2, wire)
    kA = math.cos(a * (T - wire.A_S0_C) - a * SIGMA / wire.c_A_Pa_per_C)
    kA2 = math.cos(a * (T - wire.A_S0_C) - a * sigma2 / wire.c_A_Pa_per_C)
    assert E2 == pytest.approx(0.16 * (1.0 + kA2) / (1.0 + kA), rel=1e-9)
    assert E2 > 0.16


def test_a_heating_call_above_la_gives_austenite_and_a_cooling_branch_from_it(wire):
    _, La, _, Lm = _bands(wire, SIGMA)
    E, rec = _call(initial_calls_record(1.0), +1.0, La + 0.01, SIGMA, wire)
    assert E == 0.0 and globals_of(rec)[1] == 0.0  # Ef = E above Lm
    E, rec = _call(rec, -1.0, Lm + 1.0, SIGMA, wire)
    assert E == 0.0 and globals_of(rec)[0] == 0.0  # Es re-solved through 0


def test_no_temperature_change_holds_the_last_output(wire):
    Ua, La, _, _ = _bands(wire, SIGMA)
    E, rec = _call(initial_calls_record(1.0), +1.0, 0.5 * (Ua + La), SIGMA, wire)
    held, rec2 = _call(rec, 0.0, Ua - 5.0, 0.0, wire)
    assert held == E and globals_of(rec2) == (globals_of(rec)[0], globals_of(rec)[1], E)


def test_their_output_is_not_clipped(wire):
    """Es above 1 (a cooling call far up the A band) gives E above 1 below Ua, as their function."""
    Ua, La, _, _ = _bands(wire, SIGMA)
    rec = initial_calls_record(0.9)._replace(parent_slope=0.9)  # Ef = 0.9
    E, rec = _call(rec, -1.0, La - 0.5, SIGMA, wire)
    assert E == 0.9 and globals_of(rec)[0] > 1.0
    E_low, _ = _call(rec, +1.0, Ua - 1.0, SIGMA, wire)
    assert E_low == globals_of(rec)[0] > 1.0
