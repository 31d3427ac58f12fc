"""A parameter set's fields into an :class:`~.model.OracleModel` (every derived value computed here)."""

from __future__ import annotations

import math

from smafinger.parameters import JointParameters, LinearActuatorParameters, ParameterSet
from smafinger.parameters.options import FrictionSticking, Hysteresis, JouleHeating, SpringInit, StressLaw, ThermalModel

from . import material as mat
from .model import Joint, OracleModel, Slider, Wire


def build(p: ParameterSet) -> OracleModel:
    """The oracle's model of a joint or linear bias-spring parameter set."""
    if isinstance(p, JointParameters):
        mechanism, wires = _joint(p)
    elif isinstance(p, LinearActuatorParameters):
        mechanism, wires = _slider(p)
    else:
        raise TypeError(f"the oracle has no mechanism {p.mechanism!r}")
    o = p.options
    return OracleModel(
        mechanism, tuple(wires), algebraic=o.stress_law is StressLaw.ALGEBRAIC,
        whole_wire=o.joule_heating is JouleHeating.WHOLE_WIRE, two_node=o.thermal_model is ThermalModel.TWO_NODE,
        restick=o.friction_sticking is FrictionSticking.RESTICK, damping=o.damping_switch.label,
        rule=o.hysteresis.label, reversal=p.minor_loop_reversal_C if o.hysteresis is Hysteresis.DEADBAND else 0.0,
        V_H=p.V_H_V, V_L=p.V_L_V, pwm_period=p.pwm_period_s, initial_target=p.to_si(p.initial_target))


def _wire(p: ParameterSet, name: str, spring, sigma0: float, elastic_elongation0: float, path0: float) -> Wire:
    S_w = math.pi * (p.wire_diameter_m / 2.0) ** 2
    return Wire(
        name=name, L_w=p.wire_length_m, S_w=S_w, M_w=p.wire_density_kg_m3 * S_w, A_w=math.pi * p.wire_diameter_m,
        C_p=p.specific_heat_J_kgK, R_per_m=p.resistance_ohm_per_m, T_amb=p.T_amb_C,
        h_heating=(p.h0_heating_W_m2K, p.h2_heating_W_m2K3), h_cooling=(p.h0_cooling_W_m2K, p.h2_cooling_W_m2K3),
        transformation=mat.Transformation(p.A_S0_C, p.A_F0_C, p.M_S0_C, p.M_F0_C, p.c_A_Pa_per_C, p.c_M_Pa_per_C),
        D_A=p.D_A_Pa, D_M=p.D_M_Pa, eps_R=p.eps_R, spring=spring, sigma0=sigma0,
        eps0=elastic_elongation0 / p.wire_length_m + p.eps_R * p.xi_init, path0=path0,
        xi_init=p.xi_init, T_init=p.T_init_C, latent_heat=p.latent_heat_J_kg,
        casing_capacity=p.casing_heat_capacity_J_mK, casing_loss=p.casing_loss_W_mK)


def _wire_elongation(p: ParameterSet, sigma: float) -> float:
    """Elastic elongation of the wire at stress sigma with the initial martensite fraction [m]."""
    return sigma / mat.youngs_modulus(p.xi_init, p.D_A_Pa, p.D_M_Pa) * p.wire_length_m


def _joint(p: JointParameters):
    a1, a2, a3, a4, a5 = p.a1_m, p.a2_m, p.a3_m, p.a4_m, p.a5_m
    joint = Joint(
        inertia=p.inertia_kg_m2, weight_moment=(p.mass_kg, p.gravity_m_s2, p.d_CM_m), static=p.M_SF_Nm,
        dynamic=p.M_DF_Nm, viscous_heating=p.C_DF_heating_Nms, viscous_cooling=p.C_DF_cooling_Nms,
        stick_velocity=p.stick_velocity_rad_s, q0=math.radians(p.theta0_deg), r=math.sqrt(a1 * a1 + a3 * a3),
        alpha0=(math.atan2(a1, a3), math.atan2(-a1, a3)), C=((-a5, a1), (-a4, -a1)), D=((a2, a1), (a2, -a1)))
    S_w = math.pi * (p.wire_diameter_m / 2.0) ** 2
    geo0 = joint.wire_geometry(joint.q0)
    K = p.spring_K_N_m
    x_lower = p.spring_length_lower_m - p.spring_free_length_m
    if p.options.spring_init is SpringInit.GIVEN:
        x_upper = p.spring_length_upper_m - p.spring_free_length_m
    else:  # friction-free moment balance at theta0: F_U a_U + F_L a_L + gravity = 0 (Eq. 1b)
        x_upper = -(K * x_lower * geo0[1][2] + joint.external(joint.q0)) / geo0[0][2] / K
    wires = []
    for name, x0, (path0, _, _) in zip(p.wire_names, (x_upper, x_lower), geo0):
        sigma0 = K * x0 / S_w  # the spring is below its knee at the start
        spring = mat.SpringSlack(K, x0 + p.slack_m - p.slack_band_m, p.slack_penalty_per_mm)
        wires.append(_wire(p, name, spring, sigma0, x0 + _wire_elongation(p, sigma0), path0))
    return joint, wires


def _slider(p: LinearActuatorParameters):
    slider = Slider(
        inertia=p.slider_mass_kg, spring=(p.bias_spring_K_N_m, p.bias_spring_preload_N, p.external_force_N),
        static=p.static_friction_N, dynamic=p.coulomb_friction_N, viscous_heating=p.viscous_damping_N_s_m,
        viscous_cooling=p.viscous_damping_N_s_m, stick_velocity=p.stick_velocity_m_s,
        q_min=p.stroke_min_m, q_max=p.stroke_max_m)
    S_w = math.pi * (p.wire_diameter_m / 2.0) ** 2
    sigma0 = -slider.external(0.0) / S_w  # static equilibrium at x = 0
    return slider, [_wire(p, p.wire_names[0], None, sigma0, _wire_elongation(p, sigma0), 0.0)]
