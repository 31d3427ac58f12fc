"""Trajectories: the engine (rk4, 1 ms) against ``solve_ivp`` on the plain-Python oracle, open loop.

The oracle (``tests/oracle``) stops at every discrete event and restarts: stick/slip, end stops,
a wire's driving quantity turning (T for the legacy rules, tau = T - sigma/c for the memory rule),
a legacy dead band's threshold, a memory loop's target. The engine decides these at its sub-step
starts, so an event's timing is good to one step (1 ms): that, not rk4's order, sets the errors.
Reversals at PWM edges fall on sub-step starts in both (the engine splits its steps there), so
the return-point-memory rule under PWM ripple is compared where both sides are exact.
"""

from __future__ import annotations

import math

import numpy as np
import oracle
import pytest

from smafinger import simulate
from smafinger.parameters import get

#: per-wire signals compared: the oracle's name and the engine's
WIRE_SIGNALS = {"T": "T", "xi": "xi", "T_case": "T_case"}


def trajectory_errors(p, program: str, kind: str, t_end: float) -> tuple[dict[str, float], oracle.Trajectory]:
    """Max |engine - oracle| of q and each wire signal (over wires) on a 10 ms grid, and the oracle's run."""
    ref = oracle.simulate(p, program, kind, t_end=t_end, method="LSODA", rtol=1e-8, sample_s=0.01)
    r = simulate(p, "open-loop", voltage=program, drive=kind, t_end_s=t_end, dt_s=1e-3, method="rk4",
                 output_interval_s=0.01)
    assert np.allclose(r.t, ref.t, rtol=0, atol=1e-9)
    err = {"q": float(np.max(np.abs(r.mechanism["q"] - ref.q)))}
    for key, field in WIRE_SIGNALS.items():
        err[key] = max(float(np.max(np.abs(r.wires[field][:, i] - ref.wires[w][key])))
                       for i, w in enumerate(p.wire_names))
    return err, ref


def check_exercised(p, ref: oracle.Trajectory) -> None:
    """The run exercises the model: the mechanism moves and the heated wire transforms (against the
    stop, the blocked wire's stress rises and shifts A_F up: it transforms only in part)."""
    assert np.ptp(ref.q) > (math.radians(10.0) if p.mechanism == "joint" else 9e-3)
    xi = ref.wires[p.wire_names[0]]["xi"]
    assert xi[0] == p.xi_init and xi.min() < 0.5
    if p.mechanism != "joint" and p.stroke_max_m < 0.017:
        assert ref.q.max() == p.stroke_max_m  # held at the stop


JOINT = get("paper2010")
SLIDER = get("linear-bias-spring")
#: (parameter set, program, kind, t_end [s], tolerances on q [rad or m], T [degC], xi, T_case [degC]);
#: the errors measured when these were set are in the comments (q, T, xi, T_case)
TRAJECTORIES = [
    # --- the legacy rules: the branch switches where the oracle's events put it --------------
    # 0.0145 deg (the breakaway at 2.67 s falls between two steps), 4.5e-6 degC, 1.7e-5
    pytest.param(JOINT.replace(hysteresis="deadband"), "0:8:0,6:0:0", "voltage", 20.0, math.radians(0.05), 1e-4,
                 1e-4, 0.0, id="joint-rate-law-deadband"),
    # 6.6e-4 deg, 5.4e-6 degC, 7.6e-7
    pytest.param(get("authors2020"), "0:8:0,6:0:0", "voltage", 20.0, math.radians(0.05), 1e-4, 1e-4, 0.0,
                 id="joint-algebraic-authors2020"),
    # 1.8e-3 mm, 2.7e-6 degC, 9.7e-5 (the dead band's switch at a step start, up to 1 ms late)
    pytest.param(SLIDER.replace(hysteresis="deadband", stroke_max_m=0.010), "0:1.0,1.2:0", "duty", 12.0, 2e-5,
                 1e-4, 1e-3, 0.0, id="slider-deadband-end-stop"),
    # --- the memory rule (the default) ---------------------------------------------------------
    # 0.0145 deg, 2.1e-6 degC, 1.7e-5
    pytest.param(JOINT, "0:8:0,6:0:0", "voltage", 20.0, math.radians(0.05), 1e-4, 1e-4, 0.0,
                 id="joint-rate-law-memory"),
    # two nodes and latent heat (24 kJ/kg): 0.015 deg, 3.3e-4 degC, 4.3e-6, 3.2e-6 degC (rk4 across the
    # kink in dT/dt at the band's end: 1.3e-4 degC at 0.5 ms)
    pytest.param(JOINT.replace(thermal_model="two-node", latent_heat_J_kg=24e3, casing_heat_capacity_J_mK=2.0,
                               casing_loss_W_mK=0.5), "0:8:0,6:0:0", "voltage", 20.0, math.radians(0.05), 1e-3,
                 1e-4, 1e-4, id="joint-memory-two-node-latent-heat"),
    # against an end stop at 10 mm: 1.8e-4 mm, 7.7e-6 degC, 9.4e-6
    pytest.param(SLIDER.replace(stroke_max_m=0.010), "0:1.0,1.2:0", "duty", 12.0, 2e-5, 1e-4, 1e-4, 0.0,
                 id="slider-memory-end-stop"),
    # PWM at 60 % duty (1 kHz) from just below A_S: a reversal at every edge, 56 loops wiped out
    # within steps and 5 smooth turns of tau: 2.2e-4 mm, 2.6e-8 degC, 7.3e-7
    pytest.param(SLIDER.replace(T_init_C=70.0), "0:0.6,0.3:0", "duty", 1.0, 2e-5, 1e-4, 1e-4, 0.0,
                 id="slider-memory-pwm-60-percent"),
]


@pytest.mark.parametrize("p, program, kind, t_end, tol_q, tol_T, tol_xi, tol_case", TRAJECTORIES)
def test_engine_trajectory_matches_scipy_oracle(p, program, kind, t_end, tol_q, tol_T, tol_xi, tol_case):
    err, ref = trajectory_errors(p, program, kind, t_end)
    check_exercised(p, ref)
    if p.options.thermal_model == "two-node":
        assert np.ptp(ref.wires[p.wire_names[0]]["T_case"]) > 1.0
    if p.options.hysteresis == "memory" and kind == "duty" and "0.6" in program:  # the ripple's loops
        assert ref.info["by_kind"].get("target", 0) > 10
    assert (err["q"] <= tol_q and err["T"] <= tol_T and err["xi"] <= tol_xi and err["T_case"] <= tol_case), err


def test_heating_value_damping():
    """8 V for 6 s then off: the return uses C_DF heating (0.03). Measured: q differs by 6.7 deg."""
    err, ref = trajectory_errors(JOINT.replace(damping_switch="heating-value"), "0:8:0,6:0:0", "voltage", 20.0)
    check_exercised(JOINT, ref)
    assert err["q"] <= math.radians(0.05), err


def test_memory_rule_follows_the_algebraic_stress():
    """authors2020's algebraic law with the memory rule, both wires at 80 degC (inside the A band).

    The lower wire is not heated: only its stress moves its tau. At its first motion xi_init = 1
    (above the major loop there) goes onto the major heating curve, then follows its stress.
    The engine took the direction from the state's stress rate, 0 under the algebraic law (the
    stress is no state): the lower wire's xi stayed 1.0 (oracle: 0.965) and q differed by 0.76
    deg. It now takes the solved stress's rate (Eq. 7b there): 0.011 deg and 2.8e-6.
    """
    p = get("authors2020").replace(hysteresis="memory", T_amb_C=80.0, T_init_C=80.0)
    err, ref = trajectory_errors(p, "0:8:0,3:0:0", "voltage", 6.0)
    assert ref.wires["lower"]["xi"].min() < 0.97 and ref.info["by_kind"].get("start", 0) >= 1
    r = simulate(p, "open-loop", voltage="0:8:0,3:0:0", t_end_s=6.0, dt_s=1e-3, method="rk4", output_interval_s=0.01)
    lower = np.abs(r.wires["xi"][:, 1] - ref.wires["lower"]["xi"])
    upper = np.abs(r.wires["xi"][1:, 0] - ref.wires["upper"]["xi"][1:])
    assert err["q"] <= math.radians(0.05) and lower.max() <= 1e-4 and upper.max() <= 1e-4, err


@pytest.mark.xfail(strict=True, reason=(
    "the first sample of a heated wire that starts outside the major loop under the algebraic law: "
    "the engine places xi_init = 1 at 80 degC onto the heating curve at the stress solved with xi = 1 "
    "(12.83 MPa: xi 0.97188), then solves the stress with the placed xi (13.15 MPa), where the point is "
    "behind its extreme and holds; the oracle solves the placement and the stress together (13.148 MPa, "
    "xi 0.97233, on the curve). Later samples agree within 1.5e-6: the heating passes the extreme"))
def test_the_first_sample_outside_the_loop_matches_the_oracle():
    p = get("authors2020").replace(hysteresis="memory", T_amb_C=80.0, T_init_C=80.0)
    err, _ = trajectory_errors(p, "0:8:0,3:0:0", "voltage", 6.0)
    assert err["xi"] <= 1e-4, err


def test_the_first_sample_outside_the_loop_is_placed_at_the_stress_before_it():
    """The xfail above, traced (not changed): the engine places xi on the heating curve at the
    stress solved with xi_init = 1, and the stress solved with the placed xi is higher, so the
    point (T, sigma, xi) is inside the loop, behind its extreme, where the memory rule holds it;
    the oracle's placement is the self-consistent one. Fixing it means re-placing from the old
    branch at the re-solved stress inside the memory update, whose stack is written in place."""
    from oracle.build import build
    from oracle.material import heating_curve

    p = get("authors2020").replace(hysteresis="memory", T_amb_C=80.0, T_init_C=80.0)
    r = simulate(p, "open-loop", voltage="0:8:0,3:0:0", t_end_s=0.02, dt_s=1e-3, method="rk4",
                 output_interval_s=0.01)
    upper = build(p).wires[0]
    xi0, sigma0 = r.wires["xi"][0, 0], r.wires["sigma"][0, 0]
    assert xi0 == pytest.approx(heating_curve(80.0, upper.sigma0, upper.transformation)[0], abs=1e-9)
    assert sigma0 > upper.sigma0 + 1e5  # solved with the placed xi: 13.15 against 12.83 MPa
    assert xi0 < heating_curve(80.0, sigma0, upper.transformation)[0] - 1e-4  # off the curve there


def test_the_linear_rigs_xi_follows_the_memory_rule_on_its_own_path():
    """The linear rig (algebraic law, memory rule) in closed loop: tau = T - sigma/c moves against
    T in about a tenth of the samples, and the engine followed T (found by review: xi 0.590
    where the memory operator on the engine's own (T, sigma) path gives 0.432). The operator on
    the sampled path now agrees to 6.3e-4 (the samples miss the sub-steps between them)."""
    from smafinger.model.hysteresis import KineticsMaterial
    from smafinger.model.hysteresis_drive import xi_history

    r = simulate(SLIDER, "cooperative", profile="0:0.010,4:0.004,8:0.015", t_end_s=12.0, dt_s=1e-3, method="rk4",
                 pwm="exact")
    T, S, xi = (np.asarray(r.signal(n)) for n in ("T_wire_C", "sigma_wire_Pa", "xi_wire"))
    m = KineticsMaterial(SLIDER.A_S0_C, SLIDER.A_F0_C, SLIDER.M_S0_C, SLIDER.M_F0_C, SLIDER.c_A_Pa_per_C,
                         SLIDER.c_M_Pa_per_C)
    tau = T - S / SLIDER.c_A_Pa_per_C
    assert np.sum(np.sign(np.diff(tau)) * np.sign(np.diff(T)) < 0) > 1000  # exercised
    assert np.max(np.abs(xi_history(T, S, m, xi_init=SLIDER.xi_init).xi - xi)) < 2e-3
