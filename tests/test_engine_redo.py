"""rhs.derivative_redone: re-evaluating only the wires whose inputs changed gives derivative's bits."""

import math

import numpy as np
from numba import njit

from smafinger.engine.rhs import derivative, derivative_redone, geometry
from smafinger.model.build import build_model
from smafinger.model.hysteresis import MEMORY, BranchRecord
from smafinger.model.records import Inputs, State, WireInput, WireState
from smafinger.parameters import resolve

MODEL = build_model(resolve("paper2010"))
HEATING = BranchRecord(MEMORY, 1, 0.9, 0.8, 1.0, 70.0, 0.9, math.inf, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0, 0)
COOLING = BranchRecord(MEMORY, -1, 0.86, 0.25, 0.6, 90.0, 0.1, -math.inf, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0, 0)


@njit
def _both(state, inputs_before, inputs_after, model, redo):
    geom = geometry(model, state.q)
    prev = derivative(state, inputs_before, model, geom)
    return derivative(state, inputs_after, model, geom), derivative_redone(state, inputs_after, model, geom, prev,
                                                                         redo)


def _bits(result):
    dstate, aux = result
    values = [dstate.q, dstate.v, dstate.error_integral, aux.load]
    for w in dstate.wires:
        values += list(w)
    for a in aux.wires:
        values += list(a[:-1]) + list(a.rates_per_v)  # the last field is a WireState
    return np.array(values, dtype=np.float64).tobytes()


def _inputs(upper_branch):
    wires = (WireInput(8.0, True, upper_branch, 1), WireInput(0.0, False, COOLING, 0))
    return Inputs(False, 0.03, -0.9, 1.0, False, wires)


STATE = State(-0.5, 0.3, 0.01, (WireState(77.8, 11.7e6, 0.0, 0.0, 23.0, 0.5), WireState(28.0, 7.1e6, 0.0, 0.0, 23.0, 1.0)))


def test_only_the_moved_wire_is_recomputed_with_the_same_bits():
    # the upper wire reverses (heating -> cooling branch): redo it alone
    full, redone = _both(STATE, _inputs(HEATING), _inputs(COOLING), MODEL, (True, False))
    assert _bits(full) == _bits(redone)
    assert full[0].wires[0].sigma_Pa != _both(STATE, _inputs(HEATING), _inputs(HEATING), MODEL,
                                               (False, False))[0][0].wires[0].sigma_Pa  # the branch matters


def test_a_wire_left_out_keeps_its_previous_terms():
    # redo nothing although the upper wire's branch changed: its previous (stale) rates stay
    full, stale = _both(STATE, _inputs(HEATING), _inputs(COOLING), MODEL, (False, False))
    assert _bits(full) != _bits(stale)
    before, _ = _both(STATE, _inputs(HEATING), _inputs(HEATING), MODEL, (False, False))
    assert stale[0].wires[0] == before[0].wires[0]
