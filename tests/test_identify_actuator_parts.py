"""The parts of ``identify actuator``: the unit box, the AR(1) covariance, bench runs, the rig's
controller, synthetic files in CSV and Simulink layouts."""

import math
import pathlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.linalg import toeplitz

from smafinger import simulate
from smafinger.analysis import bench_synth as bs
from smafinger.analysis.bench_runs import (BenchRunError, RigController, drive_program, load_closed_loop,
                                           load_open_loop, output_interval_for, reference_profile)
from smafinger.analysis.fit_uncertainty import ar1_times, covariance, lag1_autocorrelation
from smafinger.analysis.free_params import (DEFAULT_FREE, MIN_GAP_C, FreeBox, FreeParameterError, make_free,
                                            parse_free)
from smafinger.model.build import build_model
from smafinger.parameters import get
from smafinger.recordings import RecordingError

LINEAR = get("linear-bias-spring")
JOINT = get("paper2010")


# ---------------------------------------------------------------------------------------------
# the unit box
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("p", [LINEAR, JOINT], ids=["linear", "joint"])
def test_default_free_parameters_contain_the_start(p):
    free = parse_free(p, None)
    assert [f.name for f in free] == [r.name for r in DEFAULT_FREE[p.mechanism]]
    for f in free:
        assert f.lo <= getattr(p, f.name) <= f.hi
    box = FreeBox(p, free)
    start = box.values(box.start())
    assert start == pytest.approx({f.name: getattr(p, f.name) for f in free}, rel=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.sampled_from([LINEAR, JOINT]), st.lists(st.floats(0.0, 1.0), min_size=9, max_size=9))
def test_every_point_of_the_box_is_a_valid_ordered_set_within_the_bounds(p, u):
    box = FreeBox(p, parse_free(p, None))
    u = u[:box.n]
    q = box.params(u)  # a refused set would raise
    build_model(q)  # and so would one the engine cannot start from
    assert q.A_F0_C >= q.A_S0_C + MIN_GAP_C - 1e-9 and q.M_S0_C >= q.M_F0_C + MIN_GAP_C - 1e-9
    values = box.values(u)
    for f in box.free:
        assert f.lo - 1e-9 <= values[f.name] <= f.hi + 1e-9
    back = box.values(box.to_unit(values))
    np.testing.assert_allclose(list(back.values()), list(values.values()), rtol=1e-12, atol=1e-12)


def test_a_held_partner_narrows_the_range_and_tied_fields_move_together():
    p = LINEAR.replace(static_friction_N=0.1, coulomb_friction_N=0.1)
    box = FreeBox(p, parse_free(p, ["A_S0_C:50:90", "static_friction_N+coulomb_friction_N:0:1"]))
    assert box.values([1.0, 0.5])["A_S0_C"] == pytest.approx(p.A_F0_C - MIN_GAP_C)
    q = box.params([0.0, 0.25])
    assert q.static_friction_N == q.coulomb_friction_N == 0.25


@pytest.mark.parametrize("options, message", [
    (["nope"], "'nope' is not a numeric parameter"),
    (["name"], "not a numeric parameter"),
    (["A_S0_C:70:90"], "start value 68 (from --params) is outside the bounds"),
    (["A_S0_C:80:60"], "LO < HI"),
    (["eps_R:0:0.5"], "outside the allowed range"),
    (["A_S0_C:1:2:3"], "expected NAME or NAME:LO:HI"),
    (["A_S0_C:a:90"], "'a' is not a number"),
    (["A_S0_C", "A_S0_C"], "freed twice"),
    (["static_friction_N+coulomb_friction_N", "coulomb_friction_N"], "freed twice"),
    (["A_S0_C+M_S0_C"], "cannot be tied"),
    (["eps_R+eps_R"], "named twice"),
    (["external_force_N"], "the start value is 0; give bounds"),
])
def test_free_option_refusals(options, message):
    with pytest.raises(FreeParameterError, match=message.replace("(", r"\(").replace(")", r"\)")):
        FreeBox(LINEAR, parse_free(LINEAR, options))


def test_tied_fields_must_start_equal_and_pairs_need_room():
    with pytest.raises(FreeParameterError, match="start at different values"):
        make_free(LINEAR.replace(static_friction_N=0.2), "static_friction_N+coulomb_friction_N", 0.0, 1.0)
    with pytest.raises(FreeParameterError, match="must exceed A_S0_C's largest value"):
        p = LINEAR.replace(A_F0_C=75.0)
        FreeBox(p, parse_free(p, ["A_S0_C:60:75", "A_F0_C:70:75.2"]))


# ---------------------------------------------------------------------------------------------
# the AR(1) covariance
# ---------------------------------------------------------------------------------------------
@settings(max_examples=40, deadline=None)
@given(st.floats(-0.95, 0.99), st.integers(2, 40), st.integers(0, 2**31))
def test_ar1_times_is_the_toeplitz_product(rho, n, seed):
    X = np.random.default_rng(seed).standard_normal((n, 3))
    T = toeplitz(rho ** np.arange(n))
    np.testing.assert_allclose(ar1_times(X, rho), T @ X, rtol=1e-9, atol=1e-9)


def test_covariance_is_the_dense_sandwich():
    rng = np.random.default_rng(3)
    J = rng.standard_normal((120, 3))
    r = np.convolve(rng.standard_normal(125), np.ones(6) / 6, mode="valid")[:120]
    slices = (slice(0, 50), slice(50, 120))
    cov = covariance(J, r, slices)
    A_inv = np.linalg.inv(J.T @ J)
    meat = np.zeros((3, 3))
    for sl in slices:
        rho, s2 = lag1_autocorrelation(r[sl]), np.mean(r[sl] ** 2) * 120 / 117
        meat += J[sl].T @ (s2 * toeplitz(rho ** np.arange(sl.stop - sl.start))) @ J[sl]
    np.testing.assert_allclose(cov.ar1, A_inv @ meat @ A_inv, rtol=1e-9)
    np.testing.assert_allclose(cov.white, r @ r / 117 * A_inv, rtol=1e-12)


def test_ar1_standard_errors_match_the_scatter_of_fits_to_autocorrelated_noise():
    """Monte Carlo: a straight line fitted to AR(1) noise (rho = 0.8). The spread of the fitted
    slope over 300 data sets is what the AR(1) standard error says; the independent-residual
    one understates it by about sqrt((1 + rho) / (1 - rho)) = 3."""
    rng = np.random.default_rng(11)
    n, rho = 400, 0.8
    t = np.linspace(0.0, 1.0, n)
    J = np.column_stack([np.ones(n), t])
    slopes, se, se_white = [], [], []
    for _ in range(300):
        e = np.empty(n)
        e[0] = rng.standard_normal() / math.sqrt(1 - rho**2)
        for i in range(1, n):
            e[i] = rho * e[i - 1] + rng.standard_normal()
        coef, *_ = np.linalg.lstsq(J, 1.0 + 2.0 * t + e, rcond=None)
        cov = covariance(J, 1.0 + 2.0 * t + e - J @ coef, [slice(0, n)])
        slopes.append(coef[1])
        se.append(cov.stderr[1])
        se_white.append(cov.stderr_white[1])
    spread = np.std(slopes)
    assert np.mean(se) == pytest.approx(spread, rel=0.15)
    assert np.mean(se_white) < spread / 2.5


def test_an_unidentified_quantity_gets_an_infinite_variance():
    J = np.column_stack([np.ones(50), np.zeros(50), np.arange(50.0)])
    cov = covariance(J, np.random.default_rng(0).standard_normal(50), [slice(0, 50)])
    assert cov.rank_deficient and math.isinf(cov.stderr[1]) and np.isfinite(cov.stderr[[0, 2]]).all()


# ---------------------------------------------------------------------------------------------
# bench runs and the rig's controller
# ---------------------------------------------------------------------------------------------
def test_output_interval_divides_the_sample_times():
    assert output_interval_for(np.round(np.arange(50) * 0.01, 9)) == 0.01
    assert output_interval_for(np.round(np.arange(50) * 0.02 + 0.01, 9)) == 0.01
    assert output_interval_for(np.round(np.arange(50) * 0.01 + 0.0005, 9)) == 1e-3  # interpolated
    assert output_interval_for(np.array([0.0, 0.2, 0.5, 1.0])) == 0.1


def test_reference_profile_has_a_segment_per_change_in_user_units():
    t = np.array([0.0, 0.01, 0.02, 0.03, 0.04])
    prof = reference_profile(t, np.radians([-40.0, -40.0, -30.0, -30.0, -35.0]), JOINT)
    assert [(s.start_s, round(s.target, 9)) for s in prof.segments] == [(0.0, -40.0), (0.02, -30.0), (0.04, -35.0)]


def test_rig_controller_gains_and_clamp_in_engine_units():
    p = RigController(K_P=20.0, K_V=5.0, K_I=None, duty_max=0.25).apply(LINEAR)
    assert p.K_P_per_m == pytest.approx(100 * 20.0 / 0.25) and p.K_V_s_per_m == pytest.approx(100 * 5.0 / 0.25)
    assert p.K_I_per_m_s == pytest.approx(LINEAR.K_I_per_m_s / 0.25)
    assert p.V_H_V == pytest.approx(LINEAR.V_H_V * 0.5) and p.integral_reset == "never"
    q = RigController(K_P=1.0).apply(JOINT)
    assert q.K_P_per_rad == 100.0 and q.V_H_V == JOINT.V_H_V
    with pytest.raises(BenchRunError, match="duty_max"):
        RigController(duty_max=0.0)
    with pytest.raises(BenchRunError, match="K_V"):
        RigController(K_V=-1.0)
    with pytest.raises(BenchRunError, match="needs V_L_V = 0"):
        RigController(duty_max=0.5).apply(LINEAR.replace(V_L_V=1.0))


def test_a_duty_clamp_gives_the_mean_power_of_that_duty():
    """Eq. (11): a PID saturated at a 25 % clamp heats the wire as an open-loop 25 % duty does
    (the same mean Joule power duty x V_H^2); only the PWM ripple differs."""
    p = LINEAR.replace(A_S0_C=150.0, A_F0_C=160.0, M_S0_C=140.0, M_F0_C=130.0)  # no motion: heat alone
    rig = RigController(K_P=1e3, duty_max=0.25)
    closed = simulate(rig.apply(p), "cooperative", profile="0:0.02", t_end_s=4.0, output_interval_s=0.01)
    opened = simulate(p, "open-loop", voltage="0:0.25", drive="duty", t_end_s=4.0, output_interval_s=0.01)
    assert closed.duty_wire.min() == 100.0  # saturated throughout
    assert opened.T_wire_C[-1] - p.T_amb_C > 40.0
    np.testing.assert_allclose(closed.T_wire_C, opened.T_wire_C, atol=0.02)


def test_drive_program_puts_the_input_on_the_chosen_wire(tmp_path):
    run = bs.open_loop_run(JOINT, "0:0:0,0.2:0.5:0,0.6:0:0", 1.0, seed=1)
    bs.write_csv(tmp_path / "j.csv", run)
    rec = load_open_loop(tmp_path / "j.csv", None, "fit", JOINT).recording
    assert drive_program(rec, JOINT).steps == ((0.0, 0.0, 0.0), (0.2, 0.5, 0.0), (0.6, 0.0, 0.0))
    assert drive_program(rec, JOINT, "lower").steps[1] == (0.2, 0.0, 0.5)
    with pytest.raises(BenchRunError, match="wire 'middle' is not a wire of a joint"):
        drive_program(rec, JOINT, "middle")


def test_csv_and_simulink_mat_give_the_same_run(tmp_path):
    run = bs.open_loop_run(LINEAR, "0:0,0.3:0.4,1.5:0", 2.0, noise=2e-5, offset=1e-3, seed=4)
    bs.write_csv(tmp_path / "r.csv", run, digits=17)
    bs.write_simulink_mat(tmp_path / "r.mat", run, {"duty": ("u_pwm", 1.0), "position_m": ("x_mm", 1e3)})
    a = load_open_loop(tmp_path / "r.csv", None, "fit", LINEAR)
    b = load_open_loop(tmp_path / "r.mat", {"duty": "u_pwm", "position_m": "x_mm*1e-3"}, "fit", LINEAR)
    assert a.program == b.program and a.t_end_s == b.t_end_s == 2.0 and a.output_interval_s == 0.01
    np.testing.assert_array_equal(a.samples.t_s, b.samples.t_s)
    np.testing.assert_allclose(a.samples.values, b.samples.values, rtol=0, atol=1e-15)
    assert a.samples.exact and a.n_samples == 201 and a.baseline.sum() == 31  # at rest until 0.3 s
    assert b.recording.meta["format"] == "mat"


def test_the_baseline_ends_where_the_input_leaves_its_rest_value(tmp_path):
    """A rig idling at a small duty (a sensing current, a PWM that never quite stops) is at rest
    until its input first changes, as for closed-loop runs; the baseline used to end at the
    first input above zero, one sample, with no noise estimate (found by review)."""
    for idle in (0.0, 0.002):
        run = bs.open_loop_run(LINEAR, f"0:{idle},0.3:0.4,1.5:0", 2.0, noise=2e-5, offset=1e-3, seed=4)
        bs.write_csv(tmp_path / "r.csv", run, digits=17)
        assert load_open_loop(tmp_path / "r.csv", None, "fit", LINEAR).baseline.sum() == 31, idle


def test_bench_run_refusals(tmp_path):
    run = bs.open_loop_run(JOINT, "0:0:0,0.2:0.5:0", 0.5, seed=1)
    bs.write_csv(tmp_path / "joint.csv", run)
    with pytest.raises(RecordingError, match="the output is theta_rad but a linear-bias-spring set"):
        load_open_loop(tmp_path / "joint.csv", None, "fit", LINEAR)
    (tmp_path / "early.csv").write_text("t_s,duty,position_m\n0.0,,0.001\n0.01,0.2,0.001\n0.02,0.2,0.001\n")
    with pytest.raises(RecordingError, match="starts at -0.01 s, before the first input sample"):
        load_open_loop(tmp_path / "early.csv", None, "fit", LINEAR)
    with pytest.raises(RecordingError, match="no column 'position_ref_m'"):
        load_closed_loop(tmp_path / "early.csv", None, LINEAR, RigController())
    with pytest.raises(BenchRunError, match="role 'train'"):
        load_open_loop(tmp_path / "joint.csv", None, "train", JOINT)


def test_a_run_whose_drive_is_on_from_its_first_sample_has_no_baseline_but_that_sample(tmp_path):
    """The baseline (offset and noise) lasted while the input kept its first value, drive on or
    not: the shipped step run cut where its drive comes on counted 551 samples of heating as rest,
    giving a 5.50 mm offset (truth 1.2), 7.5 mm of "noise" and a held-out RMS/noise of 0.58
    (found by review). Now only its first sample, and no noise estimate."""
    import pandas as pd

    import smafinger
    from smafinger.analysis.bench_runs import load_open_loop
    from smafinger.parameters import resolve

    data = pathlib.Path(smafinger.__file__).parent / "data"
    df = pd.read_csv(data / "bench_step.csv", dtype=str, keep_default_na=False)
    df[df.t_s.astype(float) >= 0.5].to_csv(tmp_path / "late.csv", index=False)
    p = resolve(data / "bench_truth.toml")
    late = load_open_loop(tmp_path / "late.csv", None, "validate", p)
    assert late.baseline.sum() == 1 and late.baseline_noise() is None
    assert late.baseline_offset(p) == pytest.approx(1.2e-3, abs=2e-4)
    whole = load_open_loop(data / "bench_step.csv", None, "validate", p)
    assert whole.baseline.sum() > 10 and whole.baseline_noise() < 1e-4


def _blank_output_before(path, t_s: float, column: str = "position_m") -> None:
    """The file's output cells before ``t_s`` emptied: a logger started late."""
    import pandas as pd

    df = pd.read_csv(path, dtype=str, keep_default_na=False)
    df.loc[df.t_s.astype(float) < t_s, column] = ""
    df.to_csv(path, index=False)


def test_an_output_logged_only_after_the_drive_came_on_has_no_baseline(tmp_path):
    """The first output sample counted as at rest however late it came: a held-out run whose
    position was logged from 2.3 s after its drive came on got a "baseline" offset of 0.69 mm
    (truth 0.4), silently (found by review). Now it has no baseline, and measuring its offset is
    refused, naming the file, both times as in the file and what to do instead."""
    run = bs.open_loop_run(LINEAR, "0:0,0.3:0.4,1.5:0", 2.0, noise=2e-5, offset=1e-3, seed=4)
    bs.write_csv(tmp_path / "late.csv", run)
    _blank_output_before(tmp_path / "late.csv", 0.5)
    late = load_open_loop(tmp_path / "late.csv", None, "validate", LINEAR)
    assert late.samples.t_s[0] == pytest.approx(0.5) and late.rest_end_s == pytest.approx(0.3)
    assert late.baseline.sum() == 0 and late.baseline_noise() is None
    with pytest.raises(BenchRunError, match=r"late.csv: no output sample before the drive first turns on \(at "
                                            r"t = 0.3 s; the output starts at 0.5 s\).*--offset none.*--fit"):
        late.baseline_offset(LINEAR)
    bs.write_csv(tmp_path / "whole.csv", run)  # logged from the start: 31 samples at rest until 0.3 s
    assert load_open_loop(tmp_path / "whole.csv", None, "validate", LINEAR).baseline.sum() == 31


def test_a_replay_whose_output_starts_after_the_reference_moved_is_refused(tmp_path):
    """A closed-loop run's reference offset is measured on its baseline too: with the output
    logged only after the reference first changed there is none (it took the first sample)."""
    rig = RigController(K_P=20.0, K_V=0.5, K_I=0.0)
    run = bs.closed_loop_run(LINEAR, "0:0,0.3:0.004", rig, 1.0, noise=2e-5, offset=1e-3, seed=3)
    bs.write_csv(tmp_path / "track.csv", run)
    _blank_output_before(tmp_path / "track.csv", 0.5)
    with pytest.raises(BenchRunError, match=r"track.csv: no output sample before the reference first changes "
                                            r"\(at t = 0.3 s; the output starts at 0.5 s\).*--offset none"):
        load_closed_loop(tmp_path / "track.csv", None, LINEAR, rig)
    calibrated = load_closed_loop(tmp_path / "track.csv", None, LINEAR, rig, offset=False)
    assert calibrated.baseline.sum() == 0 and calibrated.reference_offset == 0.0


def test_a_standard_error_wider_than_the_bounds_is_not_determined():
    """null_directions scales every column of J to unit size, so a column a billion times smaller
    than the others (a temperature band a run barely reaches) passed as identified, with a finite
    standard error of 1e9 or so: M_S0_C = 55.7 +- 3.1e9 on bounds 40.7..70.7, no warning (found by
    review). Such a quantity is now marked not determined, as a null direction is."""
    from smafinger.analysis.fit_uncertainty import mark_undetermined

    t = np.linspace(0.0, 1.0, 50)
    J = np.column_stack([np.ones(50), 1e-9 * np.cos(7.0 * t), t])
    cov = covariance(J, np.random.default_rng(0).standard_normal(50), [slice(0, 50)])
    assert not cov.rank_deficient and np.isfinite(cov.stderr).all() and cov.stderr[1] > 1e6
    marked = mark_undetermined(cov, [np.inf, 30.0, 30.0])
    assert marked.rank_deficient and marked.undetermined.tolist() == [False, True, False]
    assert math.isinf(marked.stderr[1]) and math.isinf(marked.stderr_white[1])
    np.testing.assert_array_equal(marked.stderr[[0, 2]], cov.stderr[[0, 2]])
    assert mark_undetermined(cov, [np.inf, 1e12, 30.0]) is cov  # within its range: determined
    # bounds a user drew narrower than a determined quantity's standard error: the bounds fix it,
    # not "not determined" (found by review); only UNDETERMINED_WIDTHS times its range counts
    from smafinger.analysis.fit_uncertainty import UNDETERMINED_WIDTHS

    se = cov.stderr[2]
    assert mark_undetermined(cov, [np.inf, 1e12, se / (UNDETERMINED_WIDTHS * 0.99)]) is cov
    assert mark_undetermined(cov, [np.inf, 1e12, se / (UNDETERMINED_WIDTHS * 1.01)]).undetermined.tolist() == [
        False, False, True]


def test_a_value_is_flat_within_its_bounds_only_if_both_stay_within_a_noise_variance():
    """flat_within_bounds: the misfit at each bound against the solution's, in noise variances
    (SSE / dof), widened by the residuals' correlation (stderr / stderr_white)^2."""
    from smafinger.analysis.fit_uncertainty import Covariance, flat_within_bounds

    sse, dof = 100.0, 100  # noise variance 1
    cov = Covariance(ar1=np.diag([1.0, 1.0, 4.0, np.inf]), white=np.diag([1.0, 1.0, 1.0, 1.0]), rho=np.zeros(1),
                     sigma=np.ones(1), dof=dof, rank_deficient=False)
    at_bounds = sse + np.array([[0.5, 0.9],    # both within 1: flat
                                [0.5, 1.5],    # one bound beyond: determined
                                [3.0, 3.5],    # 3.5 variances, but widened 4x by the correlation: flat
                                [0.0, 0.0]])   # already not determined: left to the other rule
    assert flat_within_bounds(at_bounds, sse, cov).tolist() == [True, False, True, False]


@pytest.mark.parametrize("change, words", [
    (dict(max_nfev=0), "max_nfev = 0 must be a whole number >= 1"),
    (dict(max_nfev=1.5), "max_nfev = 1.5 must be a whole number"),
    (dict(budget=-1), "budget = -1 must be a whole number >= 0"),
    (dict(popsize=1), "popsize = 1 must be a whole number >= 2"),
    (dict(sigma0=0.0), r"sigma0 = 0.0 must be a number in \(0, 1\]"),
    (dict(diff_step=0.0), r"diff_step = 0.0 must be a number in \(0, 0.5\]"),
    (dict(dt_s=float("nan")), r"dt_s = nan must be a number in \(0, 1\]"),
])
def test_fit_settings_name_what_the_stages_cannot_use(change, words):
    """Found by an API fuzz: max_nfev 0 was an AttributeError, sigma0 0 a division by zero inside
    cma, a diff_step of 0 reported a parameter as not determined, max_nfev 1.5 no budget at all."""
    from smafinger.analysis.actuator_fit import FitSettings

    with pytest.raises(ValueError, match=words):
        FitSettings(**change)


def test_one_free_option_is_a_list_of_one():
    """parse_free(p, "A_S0_C") read the option 'A' (found by an API fuzz)."""
    from smafinger.analysis.free_params import parse_free
    from smafinger.parameters import get

    p = get("linear-bias-spring")
    assert parse_free(p, "A_S0_C") == parse_free(p, ["A_S0_C"])
