"""The records the compiled code reads and writes: ``NamedTuple``s, passed by value.

Built from a validated :class:`~smafinger.parameters.ParameterSet` by one function,
:func:`smafinger.model.build.build_model`. Numba passes a NamedTuple of floats by value (no
reference counting), so naming costs nothing at run time.

- :data:`Wire`: one row per wire. Its fields are every parameter declared with ``wire=True``
  in :mod:`smafinger.parameters.base`, *by the same name* (``h0_heating_W_m2K`` in the file,
  in the set and in the compiled code), plus the derived quantities of :data:`WIRE_DERIVED`.
  Declaring a new wire parameter there puts it here; nothing else needs to change.
- :class:`Dynamics`: the 1-DOF mechanism the wires pull on (Eqs. 1-2), with its external load.
- :class:`Controller`, :class:`Drive`: Eq. (12) and the PWM supply.
- :class:`Model`: all of it; :class:`State`, :class:`WireState`, :class:`Inputs`,
  :class:`WireInput`, :class:`Aux`, :class:`WireAux`: what the integrator carries.
"""

from __future__ import annotations

from dataclasses import fields
from typing import Any, NamedTuple

from ..parameters.base import ParameterSet

#: derived per-wire quantities: (name, meaning). Computed in :mod:`smafinger.model.build`.
WIRE_DERIVED: tuple[tuple[str, str], ...] = (
    ("area_m2", "cross-section S_w = pi d_w^2 / 4"),
    ("mass_per_length_kg_m", "M_w = rho_w S_w (Eq. 11)"),
    ("perimeter_m", "A_w = pi d_w: surface per metre of wire (Eq. 11)"),
    ("resistance_ohm", "whole-wire resistance R_w L_w (energy at the terminals)"),
    ("direction", "+1 if contracting this wire increases q, -1 if it decreases it (Sec. 2.6)"),
    ("series_rigid", "True: the wire pulls directly; False: through a spring-slack tendon (Eq. 8)"),
    ("series_K_N_m", "series spring stiffness K_S"),
    ("series_limit_m", "spring elongation beyond which the slack stiffens it (MODEL-NOTES)"),
    ("series_penalty_per_mm", "cosh penalty factor of the slack, 1/mm"),
    ("series_x0_m", "initial spring elongation"),
    ("sigma0_Pa", "initial wire stress"),
    ("eps_total0", "initial total strain, wire + spring (algebraic law)"),
    ("path0_m", "tendon path length at q0 (Eq. 6)"),
    ("route", "the wire's path to the mechanism (model.kinematics: TendonRoute, DirectPull)"),
)


def wire_parameter_names(cls: type = ParameterSet) -> tuple[str, ...]:
    """Parameters copied by name into every wire's record."""
    return tuple(f.name for f in fields(cls) if f.metadata.get("wire"))


def _make_record(name: str, field_names: tuple[str, ...], doc: str) -> type:
    rec = NamedTuple(name, [(n, Any) for n in field_names])
    rec.__module__ = __name__
    rec.__doc__ = doc
    return rec


#: one wire's parameter row (see the module docstring)
Wire = _make_record("Wire", wire_parameter_names() + tuple(n for n, _ in WIRE_DERIVED),
                    "One wire's parameters: the set's wire fields by name, and WIRE_DERIVED.")


class Dynamics(NamedTuple):
    """The mechanism's 1-DOF dynamics (Eqs. 1-2), in its generalized coordinate q.

    Joint: q = theta [rad], inertia = ``inertia_kg_m2``, friction moments ``M_SF_Nm``,
    ``M_DF_Nm``, ``C_DF_heating_Nms``, ``C_DF_cooling_Nms``. Linear actuator: q = x [m],
    inertia = ``slider_mass_kg``, friction forces ``static_friction_N``,
    ``coulomb_friction_N``, one viscous coefficient ``viscous_damping_N_s_m``.
    """

    inertia: float
    q0: float
    static_friction: float
    dynamic_friction: float
    viscous_heating: float
    viscous_cooling: float
    stick_velocity: float
    q_min: float
    q_max: float
    load: Any  #: model.dynamics.JointLoad or SliderLoad


class Controller(NamedTuple):
    """Eq. (12a) gains, DC% per SI unit of the error (per rad for the joint, per m for a slider)."""

    K_P: float
    K_V: float
    K_I: float


class Drive(NamedTuple):
    """The PWM supply (Fig. 6): V_H while on, V_L while off."""

    V_H_V: float
    V_L_V: float


class Model(NamedTuple):
    dynamics: Dynamics
    wires: tuple  #: of Wire, one per wire
    controller: Controller
    drive: Drive
    options: Any  #: parameters.options.CompiledOptions


class WireState(NamedTuple):
    """A wire's continuous state."""

    T_C: float  #: temperature
    sigma_Pa: float  #: stress (rate law; unused by the algebraic law)
    electrical_J: float  #: electrical energy delivered at its terminals
    heat_J: float  #: Joule heat the model puts into the wire (Eq. 11's P' times L_w)
    T_case_C: float  #: air inside the actuator casing (two-node model; the ambient otherwise)
    #: xi as the rate law's stress has taken it in over the sub-step: restarted at the kinetics' xi at
    #: each sub-step start, integrated with the stress (dxi/dt of Eq. 7b), caught up with xi at its end
    #: (:func:`smafinger.model.wire.transformation_catch_up`); unused by the algebraic law
    xi_integrated: float


class State(NamedTuple):
    """The continuous state the integrator advances (Table I)."""

    q: float  #: generalized coordinate (rad or m)
    v: float  #: its rate
    error_integral: float  #: integral of the control error (Eq. 12a)
    wires: tuple  #: of WireState


class WireInput(NamedTuple):
    """What is held over a sub-step for one wire."""

    drive: float  #: applied voltage [V] (or current [A] with a current drive)
    heating: bool  #: its controller's heating phase (selects h, Eq. 11)
    branch: object  #: kinetics branch, model.hysteresis.BranchRecord (Eqs. 9-10)
    depth: int  #: rows in use of the wire's reversal-point stack (return-point memory)


class Inputs(NamedTuple):
    """What is held over a sub-step."""

    stuck: bool  #: held by static friction (Eq. 2)
    viscous: float  #: viscous coefficient in force (C_DF heating or cooling)
    q_target: float  #: theta_F of Eq. (12a)
    integrating: float  #: 1.0 while the error integral runs, 0.0 while frozen (anti-windup)
    current_drive: bool  #: drive is a current [A], not a voltage
    wires: tuple  #: of WireInput


class WireAux(NamedTuple):
    """A wire's algebraic quantities at a state (outputs, discrete decisions)."""

    xi: float
    sigma_Pa: float
    force_N: float  #: tension sigma S_w
    spring_m: float  #: series spring elongation
    arm_m: float  #: moment arm b (Eqs. 4b, 5b); 1 for a slider
    dT_C_s: float
    #: how the rates of T, sigma and xi_integrated grow per unit of the mechanism's rate (d/dv;
    #: they are affine in v through Eq. 6); zeros where they are not (model.wire.wire_rates)
    rates_per_v: WireState


class Aux(NamedTuple):
    load: float  #: net load on the mechanism: M_E of Eq. (1b) (N m) or the slider's net force (N)
    wires: tuple  #: of WireAux
