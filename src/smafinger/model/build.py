"""The API edge: a validated parameter set becomes the records the compiled code reads.

:func:`build_model` is the one place where a :class:`~smafinger.parameters.ParameterSet` turns
into compiled records (:mod:`smafinger.model.records`): degrees become radians, and derived
quantities (cross-section, mass per length, tendon routes, initial spring elongations and
stresses) are computed here from the set, never stored in it.
"""

from __future__ import annotations

import math

from ..parameters.base import ParameterError, ParameterSet
from ..parameters.mechanisms import JointParameters, LinearActuatorParameters
from ..parameters.options import SpringInit
from .constitutive import youngs_modulus
from .dynamics import JointLoad, SliderLoad
from .kinematics import DirectPull, TendonRoute, wire_route
from .records import Controller, Drive, Dynamics, Model, Wire, wire_parameter_names


def build_model(p: ParameterSet) -> Model:
    """The compiled model of a parameter set (any mechanism)."""
    if isinstance(p, JointParameters):
        dynamics, controller, wires = _joint(p)
    elif isinstance(p, LinearActuatorParameters):
        dynamics, controller, wires = _slider(p)
    else:  # pragma: no cover - a new mechanism without its builder
        raise ParameterError(f"no model for mechanism {p.mechanism!r}")
    return Model(dynamics, tuple(wires), controller, Drive(p.V_H_V, p.V_L_V), p.options.compiled())


def _wire(p: ParameterSet, **derived) -> Wire:
    """A wire's record: the set's wire parameters by name, the shared derived values, ``derived``."""
    S_w = math.pi * p.wire_diameter_m**2 / 4.0
    shared = dict(area_m2=S_w, mass_per_length_kg_m=p.wire_density_kg_m3 * S_w,
                  perimeter_m=math.pi * p.wire_diameter_m,
                  resistance_ohm=p.resistance_ohm_per_m * p.wire_length_m)
    values = {n: getattr(p, n) for n in wire_parameter_names()}
    return Wire(**values, **shared, **derived)


# --------------------------------------------------------------------------------------------
# the paper's joint
# --------------------------------------------------------------------------------------------
def tendon_routes(p: JointParameters) -> tuple[TendonRoute, TendonRoute]:
    """(upper, lower) tendon routes from the MODEL-NOTES dimensions (Eq. 3)."""
    # B at theta = 0: r (cos alpha0, sin alpha0) with r and alpha0 as MODEL-NOTES gives them (that is
    # (a3, +-a1) up to rounding); the switch follows the upper B against C_U's height a1
    r = math.hypot(p.a1_m, p.a3_m)
    a0u, a0l = math.atan2(p.a1_m, p.a3_m), math.atan2(-p.a1_m, p.a3_m)
    bu, bl = (r * math.cos(a0u), r * math.sin(a0u)), (r * math.cos(a0l), r * math.sin(a0l))
    upper = TendonRoute(*bu, -p.a5_m, p.a1_m, p.a2_m, p.a1_m, *bu, p.a1_m, False)
    lower = TendonRoute(*bl, -p.a4_m, -p.a1_m, p.a2_m, -p.a1_m, *bu, p.a1_m, True)
    return upper, lower


def initial_spring_elongations(p: JointParameters) -> tuple[float, float]:
    """Initial spring elongations (upper, lower) [m].

    ``spring_init = "given"``: from the two initial spring lengths. ``"equilibrium"``: the
    lower as given, the upper from the friction-free moment balance at theta0 (Eq. 1b with
    M_E = 0), as in the authors' model.
    """
    x_l = p.spring_length_lower_m - p.spring_free_length_m
    if p.options.spring_init == SpringInit.GIVEN:
        return p.spring_length_upper_m - p.spring_free_length_m, x_l
    th0 = math.radians(p.theta0_deg)
    upper, lower = tendon_routes(p)
    b_u, b_l = wire_route(upper, th0).arm_m, wire_route(lower, th0).arm_m
    F_l = p.spring_K_N_m * x_l
    F_u = (F_l * b_l + p.mass_kg * p.gravity_m_s2 * p.d_CM_m * math.cos(th0)) / b_u
    if F_u <= 0.0:
        raise ParameterError(
            f"spring_init = 'equilibrium' needs a pulling upper tendon at theta0_deg = "
            f"{p.theta0_deg}; the moment balance gives F_upper = {F_u:.4g} N")
    return F_u / p.spring_K_N_m, x_l


def _joint(p: JointParameters):
    th0 = math.radians(p.theta0_deg)
    S_w = math.pi * p.wire_diameter_m**2 / 4.0
    K_D0 = youngs_modulus(p.xi_init, p.D_A_Pa, p.D_M_Pa) * S_w / p.wire_length_m
    wires = []
    for rt, x0, direction in zip(tendon_routes(p), initial_spring_elongations(p), (1.0, -1.0)):
        # algebraic law: total strain = elastic strain (wire + spring) + eps_R xi at the start
        eps_el0 = (x0 + x0 * p.spring_K_N_m / K_D0) / p.wire_length_m
        wires.append(_wire(
            p, direction=direction, series_rigid=False, series_K_N_m=p.spring_K_N_m,
            series_limit_m=x0 + p.slack_m - p.slack_band_m, series_penalty_per_mm=p.slack_penalty_per_mm,
            series_x0_m=x0, sigma0_Pa=p.spring_K_N_m * x0 / S_w, eps_total0=eps_el0 + p.eps_R * p.xi_init,
            path0_m=wire_route(rt, th0).path_m, route=rt))
    dynamics = Dynamics(
        inertia=p.inertia_kg_m2, q0=th0, static_friction=p.M_SF_Nm, dynamic_friction=p.M_DF_Nm,
        viscous_heating=p.C_DF_heating_Nms, viscous_cooling=p.C_DF_cooling_Nms,
        stick_velocity=p.stick_velocity_rad_s, q_min=-math.inf, q_max=math.inf,
        load=JointLoad(p.mass_kg * p.gravity_m_s2 * p.d_CM_m))
    return dynamics, Controller(p.K_P_per_rad, p.K_V_s_per_rad, p.K_I_per_rad_s), wires


# --------------------------------------------------------------------------------------------
# the linear bias-spring actuator
# --------------------------------------------------------------------------------------------
def _slider(p: LinearActuatorParameters):
    S_w = math.pi * p.wire_diameter_m**2 / 4.0
    sigma0 = (p.bias_spring_preload_N + p.external_force_N) / S_w  # static equilibrium at x = 0
    eps_total0 = sigma0 / youngs_modulus(p.xi_init, p.D_A_Pa, p.D_M_Pa) + p.eps_R * p.xi_init
    wire = _wire(p, direction=1.0, series_rigid=True, series_K_N_m=0.0, series_limit_m=0.0,
                 series_penalty_per_mm=0.0, series_x0_m=0.0, sigma0_Pa=sigma0, eps_total0=eps_total0,
                 path0_m=0.0, route=DirectPull(-1.0))
    dynamics = Dynamics(
        inertia=p.slider_mass_kg, q0=0.0, static_friction=p.static_friction_N,
        dynamic_friction=p.coulomb_friction_N, viscous_heating=p.viscous_damping_N_s_m,
        viscous_cooling=p.viscous_damping_N_s_m, stick_velocity=p.stick_velocity_m_s,
        q_min=p.stroke_min_m, q_max=p.stroke_max_m,
        load=SliderLoad(p.bias_spring_K_N_m, p.bias_spring_preload_N, p.external_force_N))
    return dynamics, Controller(p.K_P_per_m, p.K_V_s_per_m, p.K_I_per_m_s), [wire]
