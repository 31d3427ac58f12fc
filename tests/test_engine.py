"""Engine: convergence order, determinism, PWM edges, blow-up, interlock counter."""

import math

import numpy as np
import pytest

from smafinger import SimulationError, simulate
from smafinger.engine import integrators
from smafinger.engine.compiled import kernels
from smafinger.engine.kernel import memory_stacks, run_kernel
from smafinger.engine.run import _prepared, kernel_args, make_spec
from smafinger.engine.signals import new_outputs
from smafinger.model.build import build_model
from smafinger.model.kinetics import g_heating
from smafinger.parameters import get


def smooth_case():
    """Open loop at constant 8 V, no stiction, temperature inside the A band throughout.

    The wire starts at 80 degC on its heating curve (xi consistent with T and sigma), so the
    window [0, 0.4 s] crosses no band edge, stick or branch switch: a smooth ODE.
    """
    p = get("paper2010-table2").replace(M_SF_Nm=0.0, friction_sticking="initial-only",
                                        T_amb_C=80.0, T_init_C=80.0, minor_loop_reversal_C=0.0)
    sigma0 = build_model(p).wires[0].sigma0_Pa
    xi0 = g_heating(80.0, sigma0, p.A_S0_C, p.A_F0_C, p.c_A_Pa_per_C)[0]
    return p.replace(xi_init=float(xi0))


def final_state(p, method, dt):
    r = simulate(p, "open-loop", voltage="0:8:0", t_end_s=0.4, dt_s=dt, method=method, output_interval_s=0.4)
    return np.array([math.radians(r.theta_deg[-1]), r.T_upper_C[-1], r.sigma_upper_Pa[-1],
                     math.radians(r.omega_deg_s[-1])])


@pytest.mark.parametrize("name", ["euler", "rk4", "semi-implicit", "exponential", "authors-ode4"])
def test_convergence_order(name):
    p = smooth_case()
    integ = integrators.get(name)
    ref = final_state(p, "rk4", 2.5e-5)
    scale = np.array([1.0, 100.0, 1e7, 1.0])
    dts = [2e-3, 1e-3, 5e-4]
    errs = [np.max(np.abs(final_state(p, name, dt) - ref) / scale) for dt in dts]
    orders = [math.log2(errs[i] / errs[i + 1]) for i in range(len(errs) - 1)]
    assert all(abs(o - integ.order) < 0.5 for o in orders), (errs, orders)  # pre-asymptotic: 4.4 seen


def test_motion_happens_in_smooth_case():
    p = smooth_case()
    r = simulate(p, "open-loop", voltage="0:8:0", t_end_s=0.4)
    assert r.theta_deg[-1] > -40.0 + 0.1


def test_determinism_bit_identical():
    a = simulate("paper2010", "cooperative", "0:-25,reach:-55,reach:-40", t_end_s=30)
    b = simulate("paper2010", "cooperative", "0:-25,reach:-55,reach:-40", t_end_s=30)
    assert a.mechanism.tobytes() == b.mechanism.tobytes() and a.wires.tobytes() == b.wires.tobytes()
    assert a.substeps == b.substeps


def test_pwm_edges_resolved_whatever_the_step():
    """Energy of a fixed duty is exact: the edges split the steps, for any dt."""
    p = get("paper2010").replace(controller_update_s=0.0)
    energies = []
    for dt in (1e-3, 3e-4, 7e-5):
        r = simulate(p, "independent", "0:-38", t_end_s=0.05, dt_s=dt, output_interval_s=1e-3)
        energies.append(r.electrical_energy_upper_J[-1])
    # same duty sequence (updated on integer ticks) -> same on-time within the rounding of h
    assert max(energies) - min(energies) < 1e-3 * max(energies)


def test_time_grid_has_no_drift():
    r = simulate("paper2010", "cooperative", "0:-25", t_end_s=10, output_interval_s=0.001)
    assert np.array_equal(r.t, (np.arange(10001) * 1_000_000) * 1e-9)
    assert np.max(np.abs(r.t - np.arange(10001) * 1e-3)) < 1e-15 * 10


def test_blow_up_reports_time_and_state():
    p = get("paper2010").replace(inertia_kg_m2=1e-9)
    with pytest.raises(SimulationError, match=r"blow-up at t = .* theta_rad=.*omega_rad_s="):
        simulate(p, "open-loop", voltage="0:8:0", t_end_s=5.0, dt_s=1e-3)


@pytest.mark.parametrize("method, pwm", [("rk4", "averaged"), ("authors-ode4", None)])
def test_a_divergence_still_finite_is_a_blow_up(method, pwm):
    """rk4 beyond its stability limit against the joint's damping (1.5 ms; no PWM edge shortens
    the averaged PWM's steps) grows for a long time before it overflows: it returned joint angles
    of -6e14 deg as a result, its only warnings blaming the springs (found by review)."""
    with pytest.raises(SimulationError, match=r"blow-up at t = .*out of any physical range.*theta_rad="):
        simulate("paper2010", "cooperative", "0:-55", t_end_s=3.0, method=method, dt_s=5e-3, pwm=pwm)


def test_an_unstable_casing_node_is_a_blow_up():
    """An explicit casing node with a small heat capacity swung to -2,412 degC, below absolute
    zero, with no error and no warning (found by review)."""
    p = get("paper2010").replace(thermal_model="two-node", casing_heat_capacity_J_mK=5.5e-4, h2_heating_W_m2K3=0.6)
    with pytest.raises(SimulationError, match=r"blow-up at t = .*T_casing_lower_C="):
        simulate(p, "independent", "0:-46", t_end_s=10.0, method="semi-implicit", dt_s=1e-3, pwm="exact")


def test_a_stress_solve_that_fails_is_a_blow_up():
    """Under the algebraic law the stress is solved, not a state: a NaN there left the state finite
    and was recorded in 999 of 1,001 samples without an error (found by review; that case, the
    slack penalty's cosh overflowing, now has a rigid spring, and the stop is kept for any other)."""
    from smafinger.engine.substep import _aux_finite
    from smafinger.model.records import Aux, WireAux, WireState

    wa = WireAux(0.5, 1e8, 10.0, 0.0, 0.01, 0.0, WireState(0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert _aux_finite(Aux(0.1, (wa, wa)))
    for bad in (Aux(math.nan, (wa, wa)), Aux(0.1, (wa, wa._replace(sigma_Pa=math.nan))),
                Aux(0.1, (wa._replace(xi=math.inf), wa))):
        assert not _aux_finite(bad)
    p = get("paper2010").replace(wire_diameter_m=1e-5, slack_penalty_per_mm=100.0, stress_law="algebraic")
    r = simulate(p, "cooperative", "0:-30", t_end_s=1.0)
    for name in ("xi_upper", "sigma_upper_Pa", "load_Nm", "R_upper_ohm"):
        assert np.all(np.isfinite(r.signal(name))), name


def test_a_stress_root_above_the_first_bracket_is_found():
    """With a martensite stiffer than the austenite (D_A = 1e8 Pa) the stress the strain implies
    rises with the stress, both ends of the bracket [0, S(0)] were below the root, and the solve
    returned -81 MPa: a wire in compression, one sample in a run (found by review)."""
    from smafinger.model.build import build_model
    from smafinger.model.hysteresis import BranchRecord
    from smafinger.model.kinematics import wire_route
    from smafinger.model.wire import _secant_stress, algebraic_stress, total_strain

    p = get("linear-bias-spring").replace(D_A_Pa=1e8)
    w = build_model(p).wires[0]
    heating = BranchRecord(0, 1, 1.0, 1.0, 1.0, 72.55975492113824, 0.56893327483014, math.inf, 0.0, 1.0, 1.0, 1.0,
                           23.0, 0.0, 0, 0)
    T, eps = 76.79907094820038, total_strain(w, wire_route(w.route, 0.006241452827490246).path_m)
    assert _secant_stress(w, eps, T, heating, 1e7)[0] > _secant_stress(w, eps, T, heating, 0.0)[0]  # S rises
    sigma, xi, _ = algebraic_stress(w, eps, T, heating)
    assert sigma > 0.0 and sigma == pytest.approx(_secant_stress(w, eps, T, heating, sigma)[0], rel=1e-8)
    r = simulate(p, "independent", "0:0.0266,reach:-0.0099", t_end_s=2.0, controller="fuzzy-pid", hold_s=1.0,
                 tol_m=0.002, method="rk4", dt_s=1e-3, pwm="exact")
    assert float(np.min(r.sigma_wire_Pa)) >= 0.0


@pytest.mark.parametrize("numerics", [{}, {"method": "rk4", "dt_s": 1e-3}])  # the long step, the reference
def test_a_target_met_at_its_segments_start_is_reached_there(numerics):
    """The band was checked only at step ends: a target met from its segment's start was entered
    one step late (5 ms at the long step), every reach segment after it started a step late, and
    metrics.time_to_reach said 0 on the same samples (found by review)."""
    from smafinger.metrics import time_to_reach

    r = simulate("paper2010", "cooperative", "0:-40,0.5:-40,reach:-40", t_end_s=2.0, hold_s=0.2, **numerics)
    assert np.all(r.theta_deg == -40.0)  # at rest on every target
    assert r.segment_reached_s.tolist() == [0.0, 0.0, 0.0]
    assert r.segment_start_s[2] == pytest.approx(0.5 + 0.2, abs=1e-12)  # the hold after the second start
    assert time_to_reach(r.t, r.theta_deg, -40.0, 0.0, 0.5, 0.5, 0.2) == 0.0


def test_a_segment_that_never_starts_has_no_start_time():
    """Its start was -1e-9 s (the kernel's -1 marker times the tick), a time API users read as one
    (found by review)."""
    r = simulate("paper2010", "cooperative", "0:-55,reach:-25", t_end_s=1.0)
    assert r.segment_start_s[0] == 0.0 and np.isnan(r.segment_start_s[1]) and np.isnan(r.segment_reached_s[1])
    assert [seg["index"] for seg in r.summary()["segments"]] == [0]  # the summary lists the started ones


@pytest.mark.parametrize("numerics", [{}, {"method": "rk4"}])  # the long-step default, the reference
def test_interlock_counter_counts_a_forced_violation(numerics):
    spec = make_spec("paper2010", "open-loop", voltage="0:8:0", t_end_s=0.1, **numerics)
    args = kernel_args(spec)
    prog = args["prog"]
    forced = prog._replace(level=np.array([[8.0, 8.0]]), duty=np.array([[100.0, 100.0]]))  # bypasses the check
    run = args["run"]
    mech, wires = new_outputs(run.t_end_ticks // run.out_ticks + 1, 2)
    counters, _, _ = run_kernel(args["model"], run, args["segs"], forced, mech, wires,
                                np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64), memory_stacks(2))
    assert counters.violations == counters.substeps == round(0.1 / spec.dt_s)  # every sub-step counted


@pytest.mark.parametrize("strategy", ["independent", "cooperative"])
def test_interlock_never_violated_in_closed_loop(strategy):
    for prof in ("0:-25", "0:-55", "0:-25,reach:-55,reach:-40"):
        r = simulate("paper2010", strategy, prof, t_end_s=40)
        assert r.interlock_violations == 0
        both = (r.V_upper_V > 0) & (r.V_lower_V > 0)
        assert not both.any()


@pytest.mark.parametrize("profile", ["0:-25,reach:-55:lower,reach:-40", "0:-55:lower,reach:-40"])
def test_independent_waits_for_a_wire_a_segment_enabled_by_name(profile):
    """Sec. 4.1's wait applies to whichever opposing wire is still transformed: after a segment
    that enabled the lower wire by name, the strategy's next move with the upper wire starts only
    once the lower wire is back to martensite (it used to start at once, xi_lower 0.27)."""
    from smafinger.control.strategies import RELEASE_XI

    r = simulate("paper2010", "independent", profile, t_end_s=18, method="rk4")
    last = r.summary()["segments"][-1]
    after = r.t >= last["start_s"]
    first_upper = np.flatnonzero(after & (r.V_upper_V > 0))[0]
    assert r.t[first_upper] > last["start_s"] + 1.0  # the lower wire was still hot when it started
    assert r.xi_lower[first_upper] >= RELEASE_XI
    nowait = simulate("paper2010", "independent", profile, t_end_s=18, method="rk4", independent_wait=False)
    start = nowait.summary()["segments"][-1]["start_s"]
    assert nowait.t[np.flatnonzero((nowait.t >= start) & (nowait.V_upper_V > 0))[0]] < start + 0.1


@pytest.mark.parametrize("dt", [2e-3, 5e-4])
def test_output_grid_independent_of_step(dt):
    r = simulate("paper2010", "cooperative", "0:-25", t_end_s=3, dt_s=dt, output_interval_s=1e-3)
    assert not np.isnan(r.to_pandas().to_numpy()).any() and len(r.t) == 3001


@pytest.mark.parametrize("case", [
    ("paper2010", "cooperative", {"profile": "0:-25,reach:-55"}, {}),  # the long step: samples interpolated
    ("paper2010", "cooperative", {"profile": "0:-25,reach:-55"}, {"method": "rk4"}),  # the reference
    ("authors2020", "cooperative", {"profile": "0:-25,reach:-55"}, {}),  # the edge step
    ("linear-bias-spring", "open-loop", {"voltage": "0:3,2:0"}, {}),
])
def test_every_signal_of_every_sample_is_recorded(case):
    """The outputs are allocated unset but for the time row (signals.new_outputs): filled with
    NaN here, the kernel leaves none of them, in any row."""
    params, strategy, drive, numerics = case
    spec = make_spec(params, strategy, t_end_s=4.0, **drive, **numerics)
    call_args, key, mech, wires = _prepared(spec)[:4]
    mech.fill(np.nan)
    wires.fill(np.nan)
    counters = kernels(key, call_args)(*call_args)[0]
    assert counters.status == 0 and mech.shape[1] == 4001
    assert not np.isnan(mech).any() and not np.isnan(wires).any()


def _same(a, b) -> bool:
    """Equal, NaN equal to NaN (dicts and lists compared item by item)."""
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return isinstance(b, list) and len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


@pytest.mark.parametrize("case", [
    ("paper2010", "cooperative", {"profile": "0:-25,reach:-55"}, {}),  # the long step: samples interpolated
    ("paper2010", "independent", {"profile": "0:-25,reach:-55"}, {"method": "rk4"}),  # the reference
    ("authors2020", "cooperative", {"profile": "0:-25,reach:-55"}, {}),  # the edge step
    ("linear-bias-spring", "open-loop", {"voltage": "0:3,2:0"}, {}),
    ("paper2010", "open-loop", {"voltage": "0:100:0"}, {}),  # absurd: plausibility warnings
])
def test_a_run_recording_only_its_metrics_signals_has_the_same_metrics(case):
    """record="metrics" (a sweep's runs) writes signals.METRIC_FIELDS alone: the same metrics, warnings
    and sweep row as recording every signal, the same values in the signals it has, and no other."""
    from smafinger.analysis.sweep_rows import metrics_row
    from smafinger.engine.run import run_spec

    params, strategy, drive, numerics = case
    spec = make_spec(params, strategy, t_end_s=4.0, **drive, **numerics)
    full, lean = run_spec(spec), run_spec(spec, record="metrics")
    assert _same({k: v for k, v in lean.summary().items() if k != "wall_s"},
                 {k: v for k, v in full.summary().items() if k != "wall_s"})
    assert _same({k: v for k, v in metrics_row(lean).items() if k != "wall_s"},
                 {k: v for k, v in metrics_row(full).items() if k != "wall_s"})
    if "100" in str(drive):
        assert full.summary()["warnings"]
    assert set(lean.column_names) < set(full.column_names)
    for name in lean.column_names:
        assert np.array_equal(lean.signal(name), full.signal(name))
    missing = next(n for n in full.column_names if n not in lean.column_names)
    with pytest.raises(KeyError, match="recorded only its metrics' signals"):
        lean.signal(missing)
    assert np.isnan(lean.wires["V"]).all() and np.array_equal(lean.wires["T"], full.wires["T"])


def test_structured_arrays_hold_the_recorded_signals():
    """result.mechanism / result.wires (one row per sample) are the recorded rows, transposed."""
    r = simulate("paper2010", "cooperative", "0:-25", t_end_s=0.5)
    m, w = r.mechanism, r.wires
    assert m.shape == (501,) and w.shape == (501, 2)
    assert np.array_equal(m["t"], r.t_s) and np.array_equal(m["q"] * r.spec.params.coordinate.scale, r.theta_deg)
    assert np.array_equal(w["T"][:, 0], r.T_upper_C) and np.array_equal(w["sigma"][:, 1], r.sigma_lower_Pa)
    assert np.array_equal(w["R"][:, 1], r.R_lower_ohm)


def test_a_sample_left_unrecorded_is_an_error(monkeypatch):
    """The run checks that the kernel recorded every sample (a NaN time) instead of returning garbage."""
    from smafinger.engine import run as run_mod

    real = run_mod.kernels

    def skip_last(key, args):
        kernel = real(key, args)
        return lambda *a: (kernel(*a), a[4].__setitem__((0, -1), np.nan))[0]
    monkeypatch.setattr(run_mod, "kernels", skip_last)
    with pytest.raises(RuntimeError, match="1 of its 3001 output samples not recorded"):
        simulate("paper2010", "cooperative", "0:-25", t_end_s=3, engine="compiled")


def test_reached_metric_agrees_with_reach_trigger():
    """A 'reach' segment starts hold_s after the previous target was entered for good."""
    r = simulate("paper2010", "cooperative", "0:-25,reach:-55", t_end_s=20, hold_s=0.5)
    s0, s1 = r.metrics["segments"]
    assert s0["reached_s"] is not None
    assert s1["start_s"] == pytest.approx(s0["reached_s"] + 0.5, abs=2e-3)
    # the sampled-signal rule agrees within one output interval
    from smafinger.results import time_to_reach
    alt = time_to_reach(r.t, r.theta_deg, -25.0, 0.0, s1["start_s"] + 1e-3, 0.5, 0.5 - 1e-3)
    assert alt == pytest.approx(s0["reached_s"], abs=2e-3)


def test_long_pwm_voltage_program_matches_item_by_item_parse():
    from smafinger.engine.run import ticks_array, to_ticks
    from smafinger.profiles import VoltageProgram

    items = [(k * 1e-3, 8.0, 0.0) for k in range(4000)] + [(4.0, 0.0, 2.5)]
    text = ",".join(f"{t!r}:{u!r}:{v!r}" for t, u, v in items)
    prog = VoltageProgram.parse(text)
    assert prog.steps == tuple(items)
    starts = prog.arrays()[0]
    assert ticks_array("voltage start", starts).tolist() == [to_ticks("t", t, True) for t in starts]
    with pytest.raises(ValueError, match=r"voltage start \[1\] = 1e-10 s is shorter than the clock's tick"):
        ticks_array("voltage start", np.array([0.0, 1e-10]))
    with pytest.raises(ValueError, match=r"voltage start \[1\] = 1.5e-09 s is not a whole number"):
        ticks_array("voltage start", np.array([0.0, 1.5e-9]))


def test_a_low_level_that_heats_both_wires_is_warned_of():
    """V_L > 0 drives both joint wires whenever neither is pulsed: with no wire enabled both went
    to 99.8 degC and transformed, with 0 interlock violations and no warning (found by review)."""
    from smafinger.parameters import get as get_set

    hot = simulate(get_set("paper2010").replace(V_L_V=6.0), "cooperative", "0:-40:none", t_end_s=5.0, method="rk4")
    assert (hot.V_upper_V == 6.0).all() and (hot.V_lower_V == 6.0).all() and hot.interlock_violations == 0
    assert [w for w in hot.summary()["warnings"] if w.startswith("V_L_V = 6 V drives every wire")]
    assert not simulate("paper2010", "cooperative", "0:-40:none", t_end_s=5.0, method="rk4").summary()["warnings"]


def test_a_start_outside_the_major_loop_is_warned_of():
    """xi_init = 1 at 100 degC cooling towards 23 degC: the kinetics place it onto the loop at
    t = 0 (0.234), silently (found by review). A set whose start is inside gets no warning."""
    hot = simulate(get("paper2010").replace(T_init_C=100.0), strategy="open-loop", voltage="0:0:0", t_end_s=1.0)
    xi0 = float(hot.signal("xi_upper")[0])
    assert 0.2 < xi0 < 0.3
    assert any(w.startswith("upper wire: xi_init = 1 lies outside the major hysteresis loop at T_init_C = 100 degC")
               and f"starts from xi = {xi0:.4g}" in w for w in hot.summary()["warnings"])
    cold = simulate("paper2010", strategy="open-loop", voltage="0:8:0", t_end_s=1.0)
    assert not any("outside the major hysteresis loop" in w for w in cold.summary()["warnings"])
