"""The wire-resistance model (model.resistance, Eqs. R1-R2) against its closed form."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from smafinger.model.build import build_model
from smafinger.model.resistance import resistivity, wire_resistance
from smafinger.parameters import get

WIRE = build_model(get("paper2010")).wires[0]


def test_pure_phases_at_the_reference_temperature():
    T0 = WIRE.resistivity_reference_C
    assert resistivity(WIRE, T0, 0.0) == pytest.approx(8.9e-7, rel=1e-15)
    assert resistivity(WIRE, T0, 1.0) == pytest.approx(1.02e-6, rel=1e-15)
    R_A = 8.9e-7 * WIRE.wire_length_m / WIRE.area_m2
    assert wire_resistance(WIRE, T0, 0.0, 0.0) == pytest.approx(R_A, rel=1e-14)


@settings(max_examples=50, deadline=None)
@given(T=st.floats(-20.0, 200.0), xi=st.floats(0.0, 1.0), eps=st.floats(-0.01, 0.06))
def test_rule_of_mixtures_and_constant_volume(T, xi, eps):
    dT = T - WIRE.resistivity_reference_C
    rho = (xi * WIRE.resistivity_martensite_ohm_m * (1 + WIRE.resistivity_tc_martensite_per_K * dT)
           + (1 - xi) * WIRE.resistivity_austenite_ohm_m * (1 + WIRE.resistivity_tc_austenite_per_K * dT))
    assert resistivity(WIRE, T, xi) == pytest.approx(rho, rel=1e-13)
    R = wire_resistance(WIRE, T, xi, eps)
    assert R == pytest.approx(rho * WIRE.wire_length_m * (1 + eps) ** 2 / WIRE.area_m2, rel=1e-13)
    # contracting into austenite lowers the resistance (what self-sensing relies on)
    assert wire_resistance(WIRE, T, 0.0, 0.0) < wire_resistance(WIRE, T, 1.0, 0.04)
