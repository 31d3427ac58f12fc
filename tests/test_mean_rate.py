"""The wires' rates are affine in the mechanism's rate v while taut (Eq. 6), and the derivative
reports their growth per unit of v exactly: what the long-step integrators use to move the wires
at the mechanism's mean rate over a step (integrators._wires_at_mean_rate)."""

import math

from hypothesis import given, settings, strategies as st

from smafinger.engine.rhs import derivative, geometry
from smafinger.model.build import build_model
from smafinger.model.hysteresis import MEMORY, BranchRecord
from smafinger.model.records import Inputs, State, WireInput, WireState
from smafinger.parameters import resolve

HEATING = BranchRecord(MEMORY, 1, 0.9, 0.8, 1.0, 70.0, 0.9, math.inf, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0, 0)
COOLING = BranchRecord(MEMORY, -1, 0.86, 0.25, 0.6, 90.0, 0.1, -math.inf, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0, 0)
INPUTS = Inputs(False, 0.03, -0.9, 1.0, False, (WireInput(8.0, True, HEATING, 1), WireInput(0.0, False, COOLING, 0)))
MODELS = {"paper2010": build_model(resolve("paper2010")),
          "latent heat": build_model(resolve("paper2010").replace(latent_heat_J_kg=20e3))}


def _state(v, sigma_upper, sigma_lower):
    return State(-0.5, v, 0.01, (WireState(77.8, sigma_upper, 0.0, 0.0, 23.0, 0.5),
                                 WireState(28.0, sigma_lower, 0.0, 0.0, 23.0, 1.0)))


def _rates(ws):
    return ws.T_C, ws.sigma_Pa, ws.xi_integrated


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(sorted(MODELS)), st.floats(-3.0, 3.0), st.floats(-3.0, 3.0),
       st.floats(1e5, 200e6), st.floats(-5e6, 200e6))
def test_the_rates_growth_per_unit_of_v_is_exact_for_a_taut_wire(name, v0, v1, sigma_upper, sigma_lower):
    model = MODELS[name]
    at_v0 = _state(v0, sigma_upper, sigma_lower)
    geom = geometry(model, at_v0.q)
    k0, aux0 = derivative(at_v0, INPUTS, model, geom)
    k1, _ = derivative(_state(v1, sigma_upper, sigma_lower), INPUTS, model, geom)
    for i, sigma in enumerate((sigma_upper, sigma_lower)):
        per_v = _rates(aux0.wires[i].rates_per_v)
        if sigma <= 0.0:  # slack: the stress rate is floored, not affine; no growth reported
            assert per_v == (0.0, 0.0, 0.0)
            continue
        for got, r, g in zip(_rates(k1.wires[i]), _rates(k0.wires[i]), per_v):
            scale = abs(r) + abs((v1 - v0) * g)  # rounding is relative to the terms, not their sum
            assert math.isclose(got, r + (v1 - v0) * g, abs_tol=1e-12 * (1.0 + scale)), (i, got, r, g)
        assert per_v[1] != 0.0  # a taut wire's stress does follow the strain rate
