"""The default step (rk4, 1 ms, exact PWM) against a finer one under the memory hysteresis rule.

Through a slow transformation the 1 kHz PWM drives the upper wire round a minor loop every period:
xi holds while the wire cools between pulses, then follows its branch again once tau is back at
its extreme (a kink inside a sub-step). The rate-form stress (Eq. 7b) must take in the whole
of xi's increment whatever the step; before it did (``model.wire.transformation_catch_up``), the
first move of the co-operative Fig. 15 cycle took 6.112 s at 1 ms against 5.727 s at 0.25 ms, with
the upper wire's xi 0.14 apart.
"""

import math

import numpy as np
import pytest

from smafinger.engine.run import make_spec, run_spec
from smafinger.model.build import build_model
from smafinger.model.constitutive import rate_law_modulus, youngs_modulus
from smafinger.model.hysteresis import MEMORY, initial_record, new_stack, update_memory, xi_on_branch
from smafinger.model.records import WireState
from smafinger.model.wire import transformation_catch_up
from smafinger.parameters import get

#: the first move of the co-operative Fig. 15 cycle, -40 -> -25 deg (upper wire heated through A_S..A_F)
FIRST_MOVE = dict(params="paper2010", strategy="cooperative", profile="0:-25", t_end_s=7.0)
#: 1 ms against 0.25 ms: reach time [s], xi, joint angle [deg], wire temperature [degC]
#: (measured with the catch-up: 0.0005 s, 0.0009, 0.014 deg, 0.021 degC)
REACH_TOL_S, XI_TOL, Q_TOL_DEG, T_TOL_C = 0.005, 0.005, 0.05, 0.1


@pytest.fixture(scope="module")
def first_move():
    return {dt: run_spec(make_spec(**FIRST_MOVE, dt_s=dt)) for dt in (1e-3, 2.5e-4)}


def test_first_move_reach_time_converges_at_the_default_step(first_move):
    coarse, fine = first_move[1e-3], first_move[2.5e-4]
    assert coarse.spec.method == "rk4" and coarse.spec.pwm == "exact"
    assert np.isfinite(fine.segment_reached_s[0])
    assert abs(coarse.segment_reached_s[0] - fine.segment_reached_s[0]) <= REACH_TOL_S, (
        coarse.segment_reached_s, fine.segment_reached_s)


def test_first_move_traces_converge_at_the_default_step(first_move):
    coarse, fine = first_move[1e-3], first_move[2.5e-4]
    assert coarse.wires.shape == fine.wires.shape  # both sampled every 1 ms
    assert fine.wires["xi"][:, 0].min() < 0.5  # the upper wire went through its transformation
    assert np.abs(coarse.wires["xi"] - fine.wires["xi"]).max() <= XI_TOL
    assert np.abs(coarse.wires["T"] - fine.wires["T"]).max() <= T_TOL_C
    assert math.degrees(np.abs(coarse.mechanism["q"] - fine.mechanism["q"]).max()) <= Q_TOL_DEG


def _heating_branch(wire, T, sigma):
    """A memory-rule record on the major heating curve, its extreme at (T, sigma)."""
    rec, depth = initial_record(MEMORY, 1.0, T, 0.0)
    rec, _ = update_memory(rec, new_stack(), depth, T, sigma, 1, wire)
    return rec


@pytest.mark.parametrize("T_end", [92.0, 92.3, 95.0])
def test_catch_up_gives_the_stress_the_whole_increment(T_end):
    """Eq. (7b) over a sub-step that saw none of xi's increment (as RK4 stages can, across a kink):
    afterwards the stress has moved by -D_eq eps_R times xi's whole change, xi taken at the new
    stress, and the returned xi is that value (both to first order in the stress change)."""
    wire = build_model(get("paper2010")).wires[0]
    sigma = 18e6
    rec = _heating_branch(wire, 92.0, sigma)
    xi0 = xi_on_branch(rec, 92.0, sigma, wire)[0]
    ws = WireState(T_end, sigma, 0.0, 0.0, 23.0, xi0)
    new_sigma, xi_int = transformation_catch_up(wire, ws, rec)
    xi = xi_on_branch(rec, T_end, sigma, wire)[0]
    if T_end == 92.0:
        assert (new_sigma, xi_int) == (sigma, xi0)
        return
    assert xi < xi0  # heating: martensite reverts, the wire would shorten: the stress rises
    k = rate_law_modulus(wire, sigma, youngs_modulus(xi, wire.D_A_Pa, wire.D_M_Pa))[0] * wire.eps_R
    xi_new = xi_on_branch(rec, T_end, new_sigma, wire)[0]
    assert new_sigma - sigma == pytest.approx(-k * (xi_new - xi0), rel=1e-4)  # 2nd order: xi_sigma, D_eq
    assert xi_int == pytest.approx(xi_new, abs=1e-4 * (xi0 - xi_new))
