"""The linear bias-spring actuator against closed forms: heat balance, statics, stroke, a closed-loop move.

The template rig (``linear-bias-spring``) uses the algebraic stress law, so its static
positions follow from the force balance of wire and spring alone: with the slider at x (positive
= wire contracting), the wire's total strain is eps0 - x / L_w, its stress
sigma = D(xi) (eps0 - x / L_w - eps_R xi), and the spring pulls back with F0 + k x.
"""

import math

import numpy as np
import pytest

from smafinger import simulate
from smafinger.model import heat
from smafinger.parameters import get


@pytest.fixture(scope="module")
def rig():
    return get("linear-bias-spring")


def wire_constants(p):
    S_w = math.pi * p.wire_diameter_m**2 / 4
    return S_w, p.wire_density_kg_m3 * S_w, math.pi * p.wire_diameter_m


def test_steady_state_temperature_at_constant_power(rig):
    """Eq. 11 with the whole-wire reading: P' = V^2 / (R_w L_w^2) per metre, constant h."""
    h = 40.0
    p = rig.replace(h2_heating_W_m2K3=0.0, h2_cooling_W_m2K3=0.0, wire_length_m=0.8, h0_heating_W_m2K=h)
    S_w, M_w, A_w = wire_constants(p)
    V = 4.0
    P = V**2 / (p.resistance_ohm_per_m * p.wire_length_m**2)  # W per metre of wire
    T_ss = heat.steady_state_temperature(P, h, p.T_amb_C, A_w)
    tau = heat.time_constant(h, M_w, p.specific_heat_J_kgK, A_w)
    # independent hand numbers: 16 V^2 over 4.1 * 0.64 ohm m, spread over 0.8 m of a 0.5 mm wire
    assert T_ss == pytest.approx(23 + 16 / (4.1 * 0.64) / (h * math.pi * 0.5e-3), rel=1e-12)
    # rk4 requested (the rig's default too): the check is of the equation (the long step,
    # semi-implicit at 5 ms averaged, is 0.014 degC from the closed form here)
    r = simulate(p, "open-loop", voltage=f"0:{V}", t_end_s=round(6 * tau, 3), method="rk4")
    exact = T_ss + (p.T_init_C - T_ss) * np.exp(-r.t / tau)
    assert np.max(np.abs(r.T_wire_C - exact)) < 1e-6
    # the energy at the terminals is V^2 / (R_w L_w) times the time
    assert r.electrical_energy_wire_J[-1] == pytest.approx(V**2 / (p.resistance_ohm_per_m * p.wire_length_m) * r.t[-1],
                                                rel=1e-9)


def static_position(p, xi):
    """Slider position [m] where S_w D(xi) (eps0 - x/L - eps_R xi) = F0 + F_ext + k x (algebraic law)."""
    S_w = math.pi * p.wire_diameter_m**2 / 4
    F0 = p.bias_spring_preload_N + p.external_force_N
    D0 = p.D_A_Pa + p.xi_init * (p.D_M_Pa - p.D_A_Pa)
    eps0 = F0 / S_w / D0 + p.eps_R * p.xi_init
    D = p.D_A_Pa + xi * (p.D_M_Pa - p.D_A_Pa)
    k = p.bias_spring_K_N_m
    return (S_w * D * (eps0 - p.eps_R * xi) - F0) / (k + S_w * D / p.wire_length_m)


@pytest.fixture(scope="module")
def heat_cool(rig):
    """Duty 0.3 for 15 s (the wire well above A_F), then 45 s of cooling (back below M_F)."""
    return simulate(rig, "open-loop", voltage="0:0.3,15:0", drive="duty", t_end_s=60.0)


def test_hot_and_cold_static_positions_from_the_force_balance(rig, heat_cool):
    r = heat_cool
    hot = int(round(14.9 / 1e-3))
    assert r.xi_wire[hot] == 0.0 and abs(r.velocity_m_s[hot]) < 1e-9
    assert r.position_m[hot] == pytest.approx(static_position(rig, 0.0), abs=1e-9)
    assert r.xi_wire[-1] == 1.0 and abs(r.velocity_m_s[-1]) < 1e-9
    assert r.position_m[-1] == pytest.approx(static_position(rig, 1.0), abs=1e-9)
    assert static_position(rig, 1.0) == pytest.approx(0.0, abs=1e-15)  # the cold start is at rest
    # the spring balances the wire: S_w sigma = F0 + k x at both ends
    for k in (hot, -1):
        F_spring = rig.bias_spring_preload_N + rig.bias_spring_K_N_m * r.position_m[k]
        assert r.force_wire_N[k] == pytest.approx(F_spring, rel=1e-9)


def test_stroke_is_recoverable_strain_times_length_minus_the_elastic_change(rig, heat_cool):
    r = heat_cool
    hot = int(round(14.9 / 1e-3))
    stroke = r.position_m[hot] - r.position_m[-1]
    S_w = math.pi * rig.wire_diameter_m**2 / 4
    sigma_hot = (rig.bias_spring_preload_N + rig.bias_spring_K_N_m * r.position_m[hot]) / S_w
    sigma_cold = rig.bias_spring_preload_N / S_w
    elastic = rig.wire_length_m * (sigma_hot / rig.D_A_Pa - sigma_cold / rig.D_M_Pa)
    assert stroke == pytest.approx(rig.eps_R * rig.wire_length_m - elastic, rel=1e-9)
    assert 15e-3 < stroke < 20e-3  # the template rig's stroke: about 17 mm


def test_closed_loop_move_to_a_target_in_millimetres(rig):
    r = simulate(rig, "cooperative", "0:0.010,15:0.004", t_end_s=30.0)
    first, second = r.metrics["segments"]
    assert first["target_m"] == 0.010 and second["target_m"] == 0.004
    assert first["reached_s"] is not None and second["reached_s"] is not None
    assert abs(r.position_m[int(14.9e3)] - 0.010) < r.spec.tol_m
    assert abs(r.position_m[-1] - 0.004) < r.spec.tol_m
    assert r.interlock_violations == 0 and np.isfinite(r.to_pandas().to_numpy()).all()


def test_outputs_are_named_for_the_mechanism(rig):
    r = simulate(rig, "open-loop", voltage="0:0.2", drive="duty", t_end_s=0.01)
    names = r.column_names
    assert names[:4] == ["t_s", "position_m", "position_ref_m", "velocity_m_s"]
    assert {"T_wire_C", "xi_wire", "force_wire_N", "duty_wire", "electrical_energy_wire_J", "heat_wire_J"} <= set(names)
    assert not any(n.startswith(("theta", "arm_", "spring_")) for n in names)


def test_end_stops_hold_the_slider(rig):
    """A stroke limit below the free stroke: the slider rests on the stop while the wire pulls."""
    p = rig.replace(stroke_max_m=5e-3)
    r = simulate(p, "open-loop", voltage="0:0.3", drive="duty", t_end_s=10.0)
    assert np.max(r.position_m) == pytest.approx(5e-3, abs=1e-12)
    assert r.stuck[-1] == 1.0 and r.force_wire_N[-1] > p.bias_spring_preload_N + p.bias_spring_K_N_m * 5e-3
