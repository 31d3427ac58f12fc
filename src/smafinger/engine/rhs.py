"""Right-hand side of the coupled model (Table I), assembled from :mod:`smafinger.model`.

The state (:class:`~smafinger.model.records.State`) is the mechanism's coordinate and rate, the
control error's integral and each wire's temperature, stress and delivered energy. What is held
over a sub-step (voltages, kinetics branches, stick flag, viscous coefficient, target) comes in
:class:`~smafinger.model.records.Inputs`. With the algebraic stress law (authors' 2020 model)
a wire's stress is solved from its strain, temperature and xi, and its state stress is unused.
"""

import math
from typing import NamedTuple

from ..jit import njit
from ..model.dynamics import angular_acceleration, external_load, wire_load
from ..model.heat import electrical_power, joule_power_per_m
from ..model.kinematics import WireGeometry, route
from ..model.records import Aux, State, WireAux, WireState
from ..model.wire import wire_rates
from .tuples import filled, set_item


#: a wire's algebraic quantities, all zero (a typed placeholder)
ZERO_WIRE_AUX = WireAux(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, WireState(0.0, 0.0, 0.0, 0.0, 0.0, 0.0))


class Geometry(NamedTuple):
    """Everything that depends on q alone: reused while q does not change (a stuck mechanism)."""

    routes: tuple  #: per wire: model.kinematics.WireGeometry
    cos_q: float
    external: float  #: the mechanism's load apart from the wires (gravity, bias spring)


@njit(cache=True, forceinline=True)
def geometry(model, q):
    """:class:`Geometry` at coordinate q (Eqs. 3-6 and the external load of Eq. 1b)."""
    w = model.wires
    cos_q, sin_q = math.cos(q), math.sin(q)  # once for every wire (kinematics.route)
    routes = filled(w, WireGeometry(0.0, 0.0, 0.0))
    for i in range(len(w)):
        routes = set_item(routes, i, route(w[i].route, q, cos_q, sin_q))
    return Geometry(routes, cos_q, external_load(model.dynamics.load, q, cos_q))


@njit(cache=True, forceinline=True)
def geometry_at(q, q_prev, geom_prev, model):
    """geometry(model, q), reusing ``geom_prev`` (that of ``q_prev``) if q is unchanged (same bits)."""
    if q == q_prev:
        return geom_prev
    return geometry(model, q)


@njit(cache=True, forceinline=True)
def _wire_terms(model, state, inputs, geom, i):
    wire = model.wires[i]
    ws = state.wires[i]
    wi = inputs.wires[i]
    rt = geom.routes[i]
    opts = model.options
    dT, dsigma, dTc, dxi, sigma, xi, x_s, per_v = wire_rates(wire, ws, wi, rt, state.v, inputs.current_drive,
                                                              opts)
    heat = joule_power_per_m(wire, wi.drive, inputs.current_drive, opts.joule_heating) * wire.wire_length_m
    rate = WireState(dT, dsigma, electrical_power(wire, wi.drive, inputs.current_drive), heat, dTc, dxi)
    aux = WireAux(xi, sigma, sigma * wire.area_m2, x_s, rt.arm_m, dT,
                  WireState(per_v[0], per_v[1], 0.0, 0.0, 0.0, per_v[2]))
    return rate, aux, wire_load(sigma, wire.area_m2, rt.dpath_dq)


@njit(cache=True, forceinline=True)
def derivative(state, inputs, model, geom):
    """(dstate/dt, aux): the derivative of the state and the algebraic quantities (loads, xi, sigma)."""
    rates = filled(state.wires, WireState(0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    auxs = filled(state.wires, ZERO_WIRE_AUX)
    load = 0.0
    for i in range(len(state.wires)):  # one copy of the wire physics, whatever the wire count
        r, a, l_i = _wire_terms(model, state, inputs, geom, i)
        rates = set_item(rates, i, r)
        auxs = set_item(auxs, i, a)
        load += l_i
    return _with_mechanism(state, inputs, model, geom, rates, auxs, load)


@njit(cache=True, forceinline=True)
def derivative_redone(state, inputs, model, geom, prev, redo):
    """:func:`derivative` where only the wires flagged in ``redo`` (a tuple of bools) may differ
    from ``prev`` = (dstate/dt, aux) at the same state and geometry: their terms are computed
    anew, the others' taken from ``prev``. The same bits as ``derivative`` when the other wires'
    inputs are those of ``prev`` (a wire's load is recomputed from its stress, as there).
    """
    rates = prev[0].wires
    auxs = prev[1].wires
    load = 0.0
    for i in range(len(state.wires)):
        if redo[i]:
            r, a, l_i = _wire_terms(model, state, inputs, geom, i)
            rates = set_item(rates, i, r)
            auxs = set_item(auxs, i, a)
        else:
            l_i = wire_load(auxs[i].sigma_Pa, model.wires[i].area_m2, geom.routes[i].dpath_dq)
        load += l_i
    return _with_mechanism(state, inputs, model, geom, rates, auxs, load)


@njit(cache=True, forceinline=True)
def _with_mechanism(state, inputs, model, geom, rates, auxs, load):
    """The derivative from the wires' rates and summed load: the mechanism's rates (Eqs. 1-2, 12a)."""
    load += geom.external  # Eq. (1b): wires first, then gravity (or the bias spring)
    dyn = model.dynamics
    stuck = inputs.stuck
    dstate = State(
        0.0 if stuck else state.v,
        angular_acceleration(load, state.v, stuck, dyn.inertia, dyn.dynamic_friction, inputs.viscous),
        (inputs.q_target - state.q) * inputs.integrating,
        rates,
    )
    return dstate, Aux(load, auxs)
