"""Analytic checks of the model equations (Eqs. 3-5, 9-11) and the equilibrium start."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from smafinger import simulate
from smafinger.model import heat, kinetics
from smafinger.model.build import build_model
from smafinger.model.kinematics import wire_route
from smafinger.parameters import get


def both_tendons(model, theta):
    """(path_U, dpath_U, arm_U, path_L, dpath_L, arm_L) of the joint's two tendons."""
    up, lo = (wire_route(w.route, theta) for w in model.wires)
    return (*up, *lo)


def wire_constants(p):
    S_w = math.pi * p.wire_diameter_m**2 / 4
    return S_w, p.wire_density_kg_m3 * S_w, math.pi * p.wire_diameter_m


def test_eq11_constant_h_matches_closed_form():
    """Eq. 11 at constant V and h: T = T_ss + (T0 - T_ss) exp(-t/tau)."""
    h = 55.0
    p = get("paper2010").replace(h0_heating_W_m2K=h, h2_heating_W_m2K3=0.0, h0_cooling_W_m2K=h,
                                 h2_cooling_W_m2K3=0.0)
    S_w, M_w, A_w = wire_constants(p)
    T_ss = heat.steady_state_temperature(8.0**2 / p.resistance_ohm_per_m, h, p.T_amb_C, A_w)
    tau = heat.time_constant(h, M_w, p.specific_heat_J_kgK, A_w)
    # independent hand numbers: 64/8.6 W/m over h pi d; tau = rho S C_p / (h pi d)
    assert T_ss == pytest.approx(23 + (64 / 8.6) / (h * math.pi * 0.375e-3), rel=1e-12)
    assert tau == pytest.approx(6450 * 322 * 0.375e-3 / 4 / h, rel=1e-12)
    # RK4 (4th order: the closed form to 1e-6), not the long-step default (1st order in the wire)
    r = simulate(p, "open-loop", voltage="0:8:0", t_end_s=8 * tau // 1e-3 * 1e-3, method="rk4")
    t = r.t
    exact = T_ss + (p.T_init_C - T_ss) * np.exp(-t / tau)
    assert np.max(np.abs(r.T_upper_C - exact)) < 1e-6
    k = int(round(tau / 1e-3))
    # one time constant: 63.2 % of the way
    frac = (r.T_upper_C[k] - p.T_init_C) / (T_ss - p.T_init_C)
    assert frac == pytest.approx(1 - math.exp(-t[k] / tau), abs=1e-8)
    assert abs(r.T_upper_C[-1] - T_ss) < 1e-3 * (T_ss - p.T_init_C)
    # the idle wire stays at ambient exactly
    assert np.all(r.T_lower_C == p.T_amb_C)


def test_heating_rate_about_30_C_per_s():
    p = get("paper2010")
    S_w, M_w, A_w = wire_constants(p)
    rate = heat.heat_balance(23.0, 8.0**2 / 8.6, heat.convection_coefficient(23.0, 20.0, 5e-4), 23.0, M_w, 322.0, A_w)
    assert 28 < rate < 35  # MODEL-NOTES: roughly 30 degC/s from 8 V


KIN = dict(A_S0=75.0, A_F0=110.0, c_A=10.3e6, M_S0=85.0, M_F0=60.0, c_M=10.3e6)


def xi(branch, start, T, sigma, held=0.5):
    k = KIN
    return kinetics.martensite_fraction(branch, start, held, T, sigma, k["A_S0"], k["A_F0"], k["c_A"],
                                        k["M_S0"], k["M_F0"], k["c_M"])[0]


@pytest.mark.parametrize("sigma", [0.0, 10e6, 100e6])
def test_eq9_eq10_major_loop_limits(sigma):
    shift = sigma / 10.3e6
    # heating from full martensite: 1 below A_S, 0 above A_F, half-way at the middle
    assert xi(kinetics.HEATING, 1.0, 75 + shift - 0.01, sigma) == 1.0
    assert xi(kinetics.HEATING, 1.0, 110 + shift + 0.01, sigma) == 0.0
    assert xi(kinetics.HEATING, 1.0, 92.5 + shift, sigma) == pytest.approx(0.5, abs=1e-12)
    # cooling from full austenite: 0 above M_S, 1 below M_F, half-way at the middle
    assert xi(kinetics.COOLING, 0.0, 85 + shift + 0.01, sigma) == 0.0
    assert xi(kinetics.COOLING, 0.0, 60 + shift - 0.01, sigma) == 1.0
    assert xi(kinetics.COOLING, 0.0, 72.5 + shift, sigma) == pytest.approx(0.5, abs=1e-12)
    # continuity at the band edges
    for b, s, T in ((kinetics.HEATING, 1.0, 75), (kinetics.HEATING, 1.0, 110),
                    (kinetics.COOLING, 0.0, 85), (kinetics.COOLING, 0.0, 60)):
        T = T + shift
        assert abs(xi(b, s, T - 1e-7, sigma) - xi(b, s, T + 1e-7, sigma)) < 1e-6


@settings(max_examples=200, deadline=None)
@given(
    temps=st.lists(st.floats(min_value=20.0, max_value=140.0), min_size=2, max_size=12),
    sigma=st.floats(min_value=0.0, max_value=150e6),
)
def test_minor_loops_continuous_and_bounded(temps, sigma):
    """Random temperature paths with reversals inside the bands: xi in [0, 1], continuous."""
    T = 23.0
    x = 1.0
    branch = kinetics.HOLD
    start = 1.0
    k = KIN
    for target in temps:
        n = 200
        for T_next in np.linspace(T, target, n)[1:]:
            nb = kinetics.branch_of(T_next - T)
            if nb != branch:
                if nb != kinetics.HOLD:
                    start = kinetics.branch_start(nb, x, T, sigma, k["A_S0"], k["A_F0"], k["c_A"],
                                                  k["M_S0"], k["M_F0"], k["c_M"])
                    # continuity through the reversal, at the reversal temperature
                    assert abs(xi(nb, start, T, sigma) - x) < 1e-9
                branch = nb
            if branch == kinetics.HOLD:
                continue
            x_new = xi(branch, start, T_next, sigma)
            assert 0.0 <= x_new <= 1.0
            # Lipschitz bound of the cosine branches: |dxi/dT| <= pi / (2 * 25 degC)
            assert abs(x_new - x) <= math.pi / 50 * abs(T_next - T) + 1e-9
            x = x_new
            T = T_next


def hand_arm(B, P):
    """Distance from O to the line through P and B (Eqs. 4b/5b written as a cross product)."""
    d = np.subtract(B, P)
    return abs(P[0] * d[1] - P[1] * d[0]) / np.linalg.norm(d)


def test_moment_arms_and_paths_at_minus_40_deg():
    p = get("paper2010")
    model = build_model(p)
    th = math.radians(-40.0)
    # by hand (mm): r = sqrt(12.3^2 + 14.5^2) = 19.0142; B_U at angle atan(12.3/14.5) - 40 = 0.3071 deg
    r = math.sqrt(12.3**2 + 14.5**2)
    assert r == pytest.approx(19.01420, abs=1e-5)
    BU = (r * math.cos(math.radians(0.307137)), r * math.sin(math.radians(0.307137)))
    BL = (r * math.cos(math.radians(-80.307137)), r * math.sin(math.radians(-80.307137)))
    # upper wraps over D_U = (6.5, 12.3) (B_U is below C_U); lower straight from C_L = (-17.5, -12.3)
    path_u = 8.0 + math.dist(BU, (6.5, 12.3))
    path_l = math.dist(BL, (-17.5, -12.3))
    arm_u = hand_arm(BU, (6.5, 12.3))
    arm_l = hand_arm(BL, (-17.5, -12.3))
    assert arm_u == pytest.approx(13.3449, abs=1e-3)
    assert arm_l == pytest.approx(16.9448, abs=1e-3)
    pu, du, bu, pl, dl, bl = both_tendons(model, th)
    assert 1e3 * pu == pytest.approx(path_u, abs=1e-6)
    assert 1e3 * pl == pytest.approx(path_l, abs=1e-6)
    assert 1e3 * bu == pytest.approx(arm_u, abs=1e-6)
    assert 1e3 * bl == pytest.approx(arm_l, abs=1e-6)
    # the upper path shortens and the lower lengthens with extension; |d path/d theta| = arm
    assert du == pytest.approx(-bu, rel=1e-12)
    assert dl == pytest.approx(bl, rel=1e-12)
    h = 1e-6
    f = lambda t: both_tendons(model, t)  # noqa: E731
    assert (f(th + h)[0] - f(th - h)[0]) / (2 * h) == pytest.approx(du, rel=1e-6)


def test_path_continuous_at_configuration_switch():
    model = build_model(get("paper2010"))
    # the switch is where Y of B_U = a1, i.e. theta = 0 with this geometry
    lo, hi = both_tendons(model, -1e-9), both_tendons(model, 1e-9)
    assert abs(lo[0] - hi[0]) < 1e-10 and abs(lo[3] - hi[3]) < 1e-10
    assert abs(lo[2] - hi[2]) < 1e-8 and abs(lo[5] - hi[5]) < 1e-8


def test_authors2020_start_is_static_equilibrium():
    p = get("authors2020")
    upper, lower = build_model(p).wires
    th = math.radians(p.theta0_deg)
    _, _, bu, _, _, bl = both_tendons(build_model(p), th)
    S_w = upper.area_m2
    M_E = upper.sigma0_Pa * S_w * bu - lower.sigma0_Pa * S_w * bl - p.mass_kg * 9.81 * p.d_CM_m * math.cos(th)
    assert abs(M_E) < 1e-12
    # the lower spring is held at its given length (15.48 mm)
    assert lower.series_x0_m == pytest.approx(15.48e-3 - 9.17e-3, abs=1e-15)
    # left alone, the joint stays exactly where it started
    r = simulate(p, "independent", "0:-40:none", t_end_s=2.0)
    assert np.all(r.theta_deg == pytest.approx(-40.0, abs=1e-9))
    assert np.max(np.abs(r.omega_deg_s)) < 1e-9


def test_paper_spring_lengths_start_held_by_stiction():
    """MODEL-NOTES: with the paper's 17.4/15.5 mm the unbalanced moment is below M_SF."""
    p = get("paper2010").replace(spring_init="given")
    r = simulate(p, "independent", "0:-40:none", t_end_s=1.0)
    assert np.all(r.theta_deg == -40.0)
    assert r.stuck[0] == 1.0
