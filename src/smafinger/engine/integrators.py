"""Fixed-step integrators. Each declares its order of accuracy on a smooth case.

They advance a :class:`~smafinger.model.records.State` (a NamedTuple: each field of the
mechanism and of every wire) over one sub-step with the inputs held. ``k1`` = f(y) is given:
the engine evaluates it at every sub-step start for its discrete decisions anyway.

- ``euler``, ``rk4``: explicit Euler and classical Runge-Kutta. Their step is limited by the
  stiffest mode, the viscous damping -C_DF/I of Eq. (2) (-613 1/s heating, -1844 1/s cooling
  for the paper's joint): about 1.1 ms (Euler) and 1.5 ms (RK4).
- ``semi-implicit``: Euler with the damping implicit, q' = v'(new) (symplectic Euler for the
  mechanism): stable at any step against the damping; the next-stiffest mode is about 34 1/s.
  With the algebraic stress law the wire's stiffness is implicit too (linearized by a forward
  difference at the wires the step leaves, :func:`implicit_load`): there the stress follows q
  at once, and the wire's axial stiffness against the inertia is a fast, barely damped mode
  (on the linear rig omega = sqrt(kappa) = 527 rad/s at rest in martensite, more as the wire
  turns stiffer austenite)
  that no explicit update of q holds (Euler and exponential Euler drift off at every step;
  semi-implicit without it held 2 ms steps, not 5 ms: 2/omega = 3.8 ms at rest).
- ``exponential``: exponential Euler for the mechanism: (q, v) advanced exactly under the held
  load with the damping C_DF (phi functions), the wires by Euler. Like ``semi-implicit`` but
  exact for the damped motion under a constant load.
- With both, the wires are advanced at the mechanism's mean rate over the step, dq / h, not at
  its rate v at the start: a wire's rates are affine in the strain rate (Eq. 6), and the wire
  update takes (dq - h v) times their growth per unit of v
  (:func:`smafinger.model.wire.wire_rates`). Across a long step v changes by much (the damped
  mechanism settles in 1/c = 0.5-1.6 ms), and the wires' strain then followed the start's v:
  the full co-operative cycle at 10 ms steps had 0.047 deg RMS and 0.37 deg max error that way,
  0.017 and 0.13 with the mean rate.
- ``authors-ode4``: the authors' Simulink solver (ode4, classical RK4 at a fixed 1 ms step,
  MODEL-NOTES) with the PWM read at its stage times (:mod:`.pwm`, ``sampled``), the controller
  re-evaluated at every stage and its error rate from their Derivative block (:mod:`.authors`),
  and their martensite functions called at every stage with the branch of the stage's own
  dT/dt, their globals changed by every call (:mod:`smafinger.model.hysteresis_authors`), as
  their model does. Profile 2's lower-wire peak is 134.9 degC with it (their plots: 135 degC;
  123.6 degC with rk4 and the resolved PWM; docs/speed.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import NamedTuple

import math

from ..jit import njit
from ..model.records import State, WireState
from ..parameters.options import StressLaw
from .authors import call_branches, commit_calls, stage_inputs
from .rhs import derivative, geometry, geometry_at
from .tuples import set_item, with_field


class Method(IntEnum):
    EULER = 0
    RK4 = 1
    SEMI_IMPLICIT = 2
    EXPONENTIAL = 3
    AUTHORS_ODE4 = 4


@dataclass(frozen=True)
class Integrator:
    name: str
    order: int
    code: Method
    stages: int
    pwm_sampled: bool = False  #: reads the PWM at its stage times (pwm.PwmModel.SAMPLED)


EULER = Integrator("euler", order=1, code=Method.EULER, stages=1)
RK4 = Integrator("rk4", order=4, code=Method.RK4, stages=4)
SEMI_IMPLICIT = Integrator("semi-implicit", order=1, code=Method.SEMI_IMPLICIT, stages=1)
EXPONENTIAL = Integrator("exponential", order=1, code=Method.EXPONENTIAL, stages=1)
AUTHORS_ODE4 = Integrator("authors-ode4", order=4, code=Method.AUTHORS_ODE4, stages=4, pwm_sampled=True)
INTEGRATORS = {i.name: i for i in (EULER, RK4, SEMI_IMPLICIT, EXPONENTIAL, AUTHORS_ODE4)}


def get(name: str) -> Integrator:
    try:
        return INTEGRATORS[name]
    except KeyError:
        raise ValueError(f"method = {name!r} is not one of {', '.join(INTEGRATORS)}") from None


@njit(cache=True)
def _wire_axpy(a, c, b):
    return WireState(a.T_C + c * b.T_C, a.sigma_Pa + c * b.sigma_Pa, a.electrical_J + c * b.electrical_J,
                     a.heat_J + c * b.heat_J, a.T_case_C + c * b.T_case_C, a.xi_integrated + c * b.xi_integrated)


@njit(cache=True, forceinline=True)
def axpy(y, c, k):
    """y + c k, field by field."""
    ws = y.wires
    for i in range(len(ws)):
        ws = set_item(ws, i, _wire_axpy(y.wires[i], c, k.wires[i]))
    return State(y.q + c * k.q, y.v + c * k.v, y.error_integral + c * k.error_integral, ws)


@njit(cache=True, forceinline=True)
def phi12(z):
    """(phi1(z), phi2(z)) = ((e^z - 1) / z, (e^z - 1 - z) / z^2), (1, 1/2) at z = 0, from one expm1
    (exponential integrators); near 0 by their Taylor series."""
    if abs(z) < 1e-5:
        return 1.0 + 0.5 * z, 0.5 + z / 6.0 + z * z / 24.0
    e = math.expm1(z)
    if abs(z) < 1e-3:
        return e / z, 0.5 + z / 6.0 + z * z / 24.0
    return e / z, (e - z) / (z * z)


class Damping(NamedTuple):
    """The exponential integrator's phi1 and phi2 of z = -c h (:func:`phi12`), kept from step
    to step while z is the same: c = C_DF / I changes only where the damping switches between
    heating and cooling, and h only at events, so most steps reuse them (one ``expm1`` less)."""

    z: float
    phi1: float
    phi2: float


#: no step yet: z is NaN, which no z equals
NO_DAMPING = Damping(math.nan, 1.0, 0.5)


@njit(cache=True, forceinline=True)
def damping_over(c, h, prev):
    """:class:`Damping` of the damping c [1/s] over a step h [s]: ``prev`` if its z = -c h is
    this one's (the same bits), else phi12(-c h)."""
    z = -c * h
    if z == prev.z:
        return prev
    p1, p2 = phi12(z)
    return Damping(z, p1, p2)


@njit(cache=True, forceinline=True)
def implicit_load(model, y, inputs, k1, wires_end, geom):
    """(q'' to hold over the step, kappa) for the semi-implicit step with the wire's stiffness
    implicit: q'' at the start's q and v with the wires as the explicit step leaves them, and
    kappa = -d(q'')/dq [1/s^2] there, by a forward difference, >= 0.

    Only with the algebraic stress law (authors' 2020 model), where a wire's stress follows q at
    once: the wire's axial stiffness against the inertia is then a fast, barely damped mode (527
    rad/s on the linear rig at rest). Otherwise (the rate law: the stress is a state and q''
    depends on q through the geometry alone; or a stuck mechanism): (k1.v, 0).

    Both at the wires the step leaves: the step then lands where the wire's stress, having taken
    the step's whole change of temperature and so of xi, holds the load, and the stiffness is
    the transforming wire's on either side of q. At the start's wires (until 0a71aa2) a wire
    whose transformation the return-point memory held at the start had its elastic stiffness,
    16 times the transforming one on the linear rig's return to martensite, and every step ended
    one step of transformation behind its equilibrium (the stress 3.4 MPa low, 0.33 degC of
    transformation temperature at c_M 10.3 MPa/degC): the return lagged by up to 0.91 mm over the
    18 mm stroke (docs/speed.md).
    """
    if model.options.stress_law != StressLaw.ALGEBRAIC or inputs.stuck:
        return k1.v, 0.0
    k0, _ = derivative(State(y.q, y.v, y.error_integral, wires_end), inputs, model, geom)
    dq = 1e-7 * (1e-3 + abs(y.q))  # a relative step near sqrt(machine epsilon) of q [rad or m]
    q = y.q + dq
    k, _ = derivative(State(q, y.v, y.error_integral, wires_end), inputs, model, geometry(model, q))
    return k0.v, max(0.0, -(k.v - k0.v) / dq)


@njit(cache=True, forceinline=True)
def _damped_mechanism(method, y, dq_dt, a, h, c, kappa, damp):
    """(q, v) after h with the viscous damping c = C_DF / I treated implicitly or exactly.

    ``dq_dt``, ``a``: q' and q'' (k1's, or :func:`implicit_load`'s q''). v' = a0 - c v with
    a0 = a + c v held over the step. ``semi-implicit``: v1 = v + h a / (1 + c h), q1 = q + h v1;
    with a stiffness kappa > 0 (a = a0 - kappa (q - q0)), v1 = v + h (a - kappa h v) /
    (1 + c h + kappa h^2). ``exponential``: v1 = v + h phi1(-c h) a and q1 = q + h q' +
    h^2 phi2(-c h) a (exact for a constant a0), with phi1, phi2 from ``damp``
    (:func:`damping_over` of c and h). A stuck mechanism has q' = v' = 0: it stays.
    """
    if method == Method.SEMI_IMPLICIT:
        if kappa > 0.0:  # the stiffness implicit too: v1 (1 + c h + kappa h^2) = v (1 + c h) + h q''
            dv = h * (a - kappa * h * y.v) / (1.0 + c * h + kappa * h * h)
        else:
            dv = h * a / (1.0 + c * h)
        return y.q + h * (dq_dt + dv), y.v + dv
    return y.q + h * dq_dt + h * h * damp.phi2 * a, y.v + h * damp.phi1 * a


@njit(cache=True, forceinline=True)
def _wires_at_mean_rate(wires, aux, extra):
    """The wires after an explicit update taken at the mechanism's start rate v, corrected to its
    mean rate: ``extra`` = dq - h v, the mechanism's displacement beyond h v, times each wire's
    rates' growth per unit of v (``aux.wires[i].rates_per_v``)."""
    ws = wires
    for i in range(len(ws)):
        ws = set_item(ws, i, _wire_axpy(wires[i], extra, aux.wires[i].rates_per_v))
    return ws


@njit(cache=True, forceinline=True)
def step(method, model, y, h, inputs, k1, aux, geom, stages, damp):
    """y advanced by h (see the module docstring for the methods). Returns (y, evaluations,
    inputs, damp).

    ``aux``: the algebraic quantities at y, with k1 (the wires' rates' growth with v).
    ``damp``: the last step's :class:`Damping` (:data:`NO_DAMPING` at first); ``exponential``
    returns this step's, the other methods return it as given.

    RK4 as a loop over its three later stages (one right-hand-side call site, so that it is
    compiled once): the weighted sum accumulates k1 + 2 k2 + 2 k3 + k4 in that order.
    ``authors-ode4``: each later stage's inputs come from the controller at that stage's state
    and the PWM read at its phase (:func:`.authors.stage_inputs`); ``stages``
    (:class:`.authors.Stages`) is what they need; each stage is one call of the authors'
    martensite functions (:func:`.authors.call_branches`, :func:`.authors.commit_calls`), and the
    returned ``inputs`` carry their globals after the last stage (otherwise ``inputs`` as given).
    """
    if method == Method.EULER:
        return axpy(y, h, k1), 0, inputs, damp
    if method == Method.SEMI_IMPLICIT or method == Method.EXPONENTIAL:
        ye = axpy(y, h, k1)
        c = inputs.viscous / model.dynamics.inertia
        a, kappa = k1.v, 0.0
        if method == Method.SEMI_IMPLICIT:
            a, kappa = implicit_load(model, y, inputs, k1, ye.wires, geom)
        else:
            damp = damping_over(c, h, damp)
        q, v = _damped_mechanism(method, y, k1.q, a, h, c, kappa, damp)
        wires = _wires_at_mean_rate(ye.wires, aux, (q - y.q) - h * k1.q)
        return State(q, v, ye.error_integral, wires), 0, inputs, damp
    half = 0.5 * h
    acc = k1
    k = k1
    q_prev = y.q
    g = geom
    for stage in range(3):
        yk = axpy(y, h if stage == 2 else half, k)
        g = geometry_at(yk.q, q_prev, g, model)
        q_prev = yk.q
        inp = inputs
        if method == Method.AUTHORS_ODE4:
            since = h if stage == 2 else half
            inp = stage_inputs(model, inputs, yk, stages, stages.phase_end if stage == 2 else stages.phase_mid, since)
            inp = call_branches(model, yk, inp)
        k, aux = derivative(yk, inp, model, g)
        if method == Method.AUTHORS_ODE4:
            inputs = with_field(inputs, "wires", commit_calls(model, yk, inp, aux).wires)
        acc = axpy(acc, 1.0 if stage == 2 else 2.0, k)
    return axpy(y, h / 6.0, acc), 3, inputs, damp
