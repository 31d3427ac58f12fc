"""The metrics of :mod:`smafinger.metrics` on signals whose answer is known."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from smafinger import metrics as M
from smafinger import simulate

T = np.round(np.arange(0.0, 20.0 + 1e-9, 1e-3), 9)  # a 1 ms grid, like a run's output
signals = st.lists(st.floats(-60.0, 60.0, allow_nan=False), min_size=2, max_size=200).map(np.array)


# ---- building blocks ------------------------------------------------------------------------
def test_window_includes_its_edges_within_half_a_tick():
    t = np.array([0.999999999, 1.0, 2.0, 2.0000000004, 2.000000001])
    assert M.window(t, 1.0, 2.0).tolist() == [False, True, True, True, False]


@settings(max_examples=200, deadline=None)
@given(n=st.integers(0, 50), dt=st.sampled_from([1e-3, 5e-3, 0.1]), a=st.floats(-1.0, 6.0), width=st.floats(0.0, 6.0),
       nudge=st.sampled_from([0.0, 0.4e-9, -0.4e-9, 0.6e-9]))
def test_window_slice_picks_the_samples_of_the_window(n, dt, a, width, nudge):
    """On an ascending output grid the bisected slice holds exactly the window's samples,
    edges within half a tick included (the segment metrics use the slice)."""
    t = np.arange(n) * dt
    a = round(a / dt) * dt + nudge  # starts on and beside samples too
    b = a + width
    np.testing.assert_array_equal(t[M.window_slice(t, a, b)], t[M.window(t, a, b)])


def test_overshoot_is_measured_in_the_direction_of_the_motion():
    th = np.array([-40.0, -35.0, -29.5, -30.2, -30.0])
    assert M.overshoot_deg(th, -30.0, M.motion_direction(-40.0, -30.0)) == pytest.approx(0.5)
    flexion = np.array([-20.0, -25.0, -30.3, -29.9])
    assert M.overshoot_deg(flexion, -30.0, M.motion_direction(-20.0, -30.0)) == pytest.approx(0.3)
    assert M.overshoot_deg(th, -30.0, 0.0) == 0.0
    assert M.overshoot_deg(np.array([-40.0, -35.0]), -30.0, 1.0) == 0.0


@given(signals, st.floats(-60.0, 60.0), st.sampled_from([-1.0, 1.0]))
def test_overshoot_is_nonnegative_and_mirror_symmetric(th, target, direction):
    ov = M.overshoot_deg(th, target, direction)
    assert ov >= 0.0
    assert M.overshoot_deg(-th, -target, -direction) == ov
    assert np.all(direction * (th - target) <= ov)


def test_motion_start_on_a_ramp():
    th = -40.0 + 3.0 * T  # 3 deg/s: 0.1 deg after 0.0333 s, 0.5 deg after 0.1667 s
    assert M.motion_start_s(T, th) == pytest.approx(0.034)
    assert M.motion_start_s(T, th, threshold_deg=0.5) == pytest.approx(0.167)
    assert M.motion_start_s(T, np.full_like(T, -40.0)) is None


@given(signals, st.floats(0.01, 5.0))
def test_before_the_start_of_motion_the_joint_is_within_the_threshold(th, thr):
    t = np.arange(th.size, dtype=float)
    start = M.motion_start_s(t, th, thr)
    before = t < (np.inf if start is None else start)
    assert np.all(np.abs(th[before] - th[0]) <= thr)
    if start is not None:
        assert abs(th[int(start)] - th[0]) > thr


def test_settle_time_of_a_decaying_oscillation():
    th = -40.0 + 2.0 * np.exp(-T) * np.cos(2 * np.pi * T)
    s = M.settle_time(T, th, -40.0, 0.0, 20.0, band_deg=0.1)
    # the envelope 2 e^-t falls below 0.1 deg at t = ln 20 = 3.0 s; the oscillation is inside sooner
    assert 2.0 < s <= np.log(20.0) + 1e-3
    assert np.all(np.abs(th[T >= s] + 40.0) <= 0.1)
    assert np.abs(th[T < s][-1] + 40.0) > 0.1
    assert M.settle_time(T, np.full_like(T, -40.0), -40.0, 0.0, 20.0) == 0.0
    assert M.settle_time(T, -40.0 + T, -40.0, 0.0, 20.0) is None


def test_time_to_reach_needs_the_hold():
    th = np.where(T < 3.0, -40.0 + 5.0 * T, -25.0)
    th[(T > 4.0) & (T < 4.2)] = -24.0  # a brief excursion out of the 0.5 deg band
    assert M.time_to_reach(T, th, -25.0, 0.0, 20.0, 0.5, 0.5) == pytest.approx(2.9, abs=1e-9)
    assert M.time_to_reach(T, th, -25.0, 0.0, 20.0, 0.5, 2.0) == pytest.approx(4.2, abs=1e-9)
    assert M.time_to_reach(T, th, -25.0, 0.0, 20.0, 0.5, 30.0) is None


def test_martensite_time():
    xi = np.clip(0.2 + 0.1 * T, 0.0, 1.0)  # 1 at t = 8 s
    assert M.martensite_time(T, xi, 2.0) == pytest.approx(5.99, abs=2e-3)
    assert M.martensite_time(T, xi, 9.0) is None  # already martensite: nothing to wait for
    assert M.martensite_time(T, np.full_like(T, 0.5), 0.0) is None


def test_increase_of_a_cumulative_signal():
    assert M.increase(T, 3.0 * T, 2.0, 5.0) == pytest.approx(9.0)


# ---- open loop and the cooling phase ---------------------------------------------------------------
def test_openloop_metrics_on_a_known_signal():
    # rise 3 deg/s from t = 1 s to a 10 deg range at 4.33 s, held until the voltage goes off
    # at 10 s, then back to 1 deg with a time constant of 1 s
    up = np.clip(3.0 * (T - 1.0), 0.0, 10.0)
    down = 1.0 + 9.0 * np.exp(-(T - 10.0))
    th = -40.0 + np.where(T <= 10.0, up, down)
    m = M.openloop_metrics(T, th, 10.0)
    assert m["range_deg"] == pytest.approx(10.0)
    assert m["start_s"] == pytest.approx(1.034)
    assert m["rise90_s"] == pytest.approx(4.0, abs=1e-9)
    assert m["still_moving_deg_s"] == 0.0
    assert m["angle_at_off_deg"] == pytest.approx(-30.0)
    assert m["final_deg"] == pytest.approx(-39.0, abs=1e-3)
    # 0.1 deg back after ln(90 / 89.0) s; 90 % of the way after ln(10) s
    assert m["return_start_s"] == pytest.approx(np.log(9.0 / 8.9), abs=1e-3)
    assert m["return90_s"] == pytest.approx(np.log(10.0), abs=2e-3)
    flat = M.openloop_metrics(T, np.full_like(T, -40.0), 10.0)
    assert flat["range_deg"] == 0.0 and flat["start_s"] is None and flat["return90_s"] is None


def test_cooling_phase_metrics_on_a_known_signal():
    t = np.arange(0.0, 10.0, 0.01)
    theta = np.where(t < 2.0, -40.0 + 5.0 * t, -30.0 + 0.2 * np.sin(np.pi * (t - 2.0) / 3.0))
    T_C = 90.0 - 2.0 * t
    m = M.cooling_phase_metrics(t, theta, T_C, -30.0)
    assert m["cooling_start_s"] == pytest.approx(2.01)
    assert m["cooling_s"] == pytest.approx(3.0, abs=0.011)
    assert m["cooling_rate_C_s"] == pytest.approx(2.0)
    assert m["overshoot_deg"] == pytest.approx(0.2, abs=1e-3)
    assert m["fall_back_deg"] == pytest.approx(0.2, abs=1e-3)
    flat = M.cooling_phase_metrics(t, np.full_like(t, -35.0), T_C, -30.0)
    assert flat["cooling_s"] is None and flat["overshoot_deg"] == 0.0 and flat["fall_back_deg"] is None


def test_cooling_phase_overshoot_is_the_one_definition():
    """The overshoot of the cooling-phase metrics is overshoot_deg of the whole move; the fall back
    is the same function against the move's direction, after the phase."""
    t = np.arange(0.0, 12.0, 0.01)
    theta = np.where(t < 2.0, -40.0 + 5.0 * t, -30.0 + 0.3 * np.sin(np.pi * (t - 2.0) / 2.0) * np.exp(-(t - 2.0) / 4))
    m = M.cooling_phase_metrics(t, theta, 90.0 - t, -30.0)
    assert m["overshoot_deg"] == M.overshoot_deg(theta, -30.0, M.motion_direction(-40.0, -30.0))
    after = M.window(t, m["cooling_start_s"] + m["cooling_s"], m["cooling_start_s"] + m["cooling_s"] + M.COOLING_WINDOW_S)
    assert m["fall_back_deg"] == M.overshoot_deg(theta[after], -30.0, -1.0) > 0.0


def test_rest_time_after_the_last_fast_sample():
    v = np.where(T < 4.0, 2.0, 0.0)
    v[(T > 6.0) & (T < 6.5)] = 0.06  # slow creep above the threshold
    assert M.rest_time(T, v, 0.0, 20.0) == pytest.approx(6.5, abs=2e-3)
    assert M.rest_time(T, v, 0.0, 20.0, threshold=0.1) == pytest.approx(4.0, abs=2e-3)
    assert M.rest_time(T, np.zeros_like(T), 0.0, 20.0) == 0.0
    assert M.rest_time(T, np.ones_like(T), 0.0, 20.0) is None


def test_cooled_time_waits_for_every_wire_it_started_with_transformed():
    hot = np.clip(0.2 + 0.1 * T, 0.0, 1.0)  # martensite (0.999) at 7.99 s
    hotter = np.clip(-0.6 + 0.1 * T, 0.0, 1.0)  # at 15.99 s
    cold = np.ones_like(T)
    assert M.cooled_time(T, {"a": hot, "b": cold}, 2.0, 20.0) == pytest.approx(5.99, abs=2e-3)
    assert M.cooled_time(T, {"a": hot, "b": hotter}, 2.0, 20.0) == pytest.approx(13.99, abs=2e-3)
    assert M.cooled_time(T, {"a": hot, "b": hotter}, 2.0, 10.0) is None  # not back before the end
    assert M.cooled_time(T, {"b": cold}, 2.0, 20.0) == 0.0
    # a wire transformed during the window (martensite at its start) does not count
    heated = np.where(T < 5.0, 1.0, 0.3)
    assert M.cooled_time(T, {"a": hot, "c": heated}, 2.0, 20.0) == pytest.approx(5.99, abs=2e-3)


def test_onoff_cycles_on_a_known_signal():
    """Two cycles: the casing rises 2 degC per cycle and keeps it; the joint returns exponentially,
    with a time constant that doubles in the second cycle."""
    t = np.round(np.arange(0.0, 40.0 + 1e-9, 1e-3), 9)
    on = ((0.0, 5.0), (20.0, 25.0))
    theta = np.full_like(t, -40.0)
    casing = 23.0 + np.where(t < 20.0, 2.0 * np.minimum(t, 5.0) / 5.0, 2.0 + 2.0 * np.minimum(t - 20.0, 5.0) / 5.0)
    xi = np.ones_like(t)
    for (a, b), tau in zip(on, (1.0, 2.0)):
        heat, cool = (t >= a) & (t <= b), t > b
        theta[heat] = -40.0 + 3.0 * (t[heat] - a)
        seg = cool & (t < a + 20.0)
        theta[seg] = -40.0 + 15.0 * np.exp(-(t[seg] - b) / tau)
        xi[heat] = 0.5
        xi[seg] = np.where(t[seg] - b < tau, 0.5, 1.0)
    c = M.onoff_cycle_metrics(t, theta, 100.0 - 0.0 * t, casing, xi, on)
    assert [x["casing_start_C"] for x in c] == [23.0, 25.0]
    assert [x["casing_end_C"] for x in c] == pytest.approx([25.0, 27.0])
    assert [x["range_deg"] for x in c] == pytest.approx([15.0, 15.0])
    # 90% of the way back after tau ln 10
    assert [x["cooling_s"] for x in c] == pytest.approx([np.log(10.0), 2.0 * np.log(10.0)], abs=2e-3)
    assert [x["martensite_s"] for x in c] == pytest.approx([1.0, 2.0], abs=2e-3)
    assert c[1]["end_s"] == 40.0 and c[0]["end_s"] == 20.0


def test_segment_energy_is_named_for_what_it_is():
    span = M.Span(0, 0.0, 10.0, -30.0, "upper", 4.0)
    elec, heat = {"upper": 3.0 * T}, {"upper": 0.5 * T}
    seg = M.segment_metrics(T, -40.0 + T, span, {"upper": 20.0 + T}, elec, heat_J=heat)
    assert seg["electrical_energy_J"] == seg["energy_J"] == {"upper": pytest.approx(30.0)}
    assert seg["heat_J"] == {"upper": pytest.approx(5.0)}


# ---- cycles ---------------------------------------------------------------------------------
def _segments(reached, hold_s=0.5):
    out, start = [], 0.0
    for i, r in enumerate(reached):
        out.append({"index": i, "start_s": start, "reached_s": r})
        if r is None:
            break
        start += r + hold_s
    return out


@settings(max_examples=50)
@given(st.lists(st.floats(0.1, 20.0), min_size=1, max_size=5), st.floats(0.0, 3.0))
def test_cycle_time_on_reach_is_the_sum_of_reached_s(reached, hold_s):
    segs = _segments(reached, hold_s)
    n = len(segs)
    cyc = M.cycle_time(segs, n, n_on_reach=n - 1, hold_s=hold_s)
    assert cyc == pytest.approx(M.reached_sum(segs, n), abs=1e-9)
    assert M.elapsed_time(segs, n) == pytest.approx(cyc + (n - 1) * hold_s, abs=1e-9)


def test_a_cycle_that_does_not_finish_has_no_time():
    segs = _segments([5.0, None])
    assert M.elapsed_time(segs, 2) is None and M.cycle_time(segs, 2, 1, 0.5) is None
    assert M.reached_sum(segs, 2) is None


def test_a_cycle_whose_last_segments_never_started_has_no_time():
    """Every segment that started was reached, but the run ended before the last one's start
    time: the time of that part of the cycle was reported as the cycle's (found by review: 15.05 s
    for '0:-25,10:-55,30:-40' over 20 s)."""
    segs = _segments([5.0, 4.0])
    assert M.elapsed_time(segs, 3) is None and M.cycle_time(segs, 3, 0, 0.5) is None
    assert M.reached_sum(segs, 3) is None
    assert M.elapsed_time(segs, 2) == pytest.approx(9.5)
    # a cool-down (no actuator enabled) is not a target to reach: authors2020's profile 1
    cool = [{"index": 0, "start_s": 0.0, "reached_s": 3.3, "enable": "upper"},
            {"index": 1, "start_s": 5.0, "reached_s": None, "enable": "none"},
            {"index": 2, "start_s": 10.0, "reached_s": 2.3, "enable": "upper"}]
    assert M.elapsed_time(cool, 3) == pytest.approx(12.3) and M.reached_sum(cool, 3) == pytest.approx(5.6)
    assert M.elapsed_time([dict(cool[0], reached_s=None, enable="upper")] + cool[1:], 3) is None
    from smafinger.paper.derived import cycle_metrics

    r = simulate("paper2010", "cooperative", "0:-25,10:-55,30:-40", t_end_s=20.0)
    assert [s["index"] for s in r.summary()["segments"]] == [0, 1]
    assert cycle_metrics(r) == {"cycle_s": None, "elapsed_s": None, "reached_sum_s": None}


def test_reduction():
    assert M.reduction(37.5, 27.5) == pytest.approx(10.0 / 37.5)
    assert M.reduction(None, 27.5) is None


def test_a_target_never_pursued_is_said_and_has_no_overshoot():
    """'0:-25,reach:-55,3:-40': -25 deg is reached after 3 s, so the -55 deg segment starts and
    ends in the same instant. Its overshoot was reported as 0.0 beside energies of None, and
    nothing said the target was skipped (found by review)."""
    r = simulate("paper2010", "cooperative", "0:-25,reach:-55,3:-40", t_end_s=12.0)
    s = r.summary()
    seg1 = next(x for x in s["segments"] if x["index"] == 1)
    assert seg1["start_s"] == seg1["end_s"] and seg1["overshoot_deg"] is None
    assert seg1["peak_temperature_C"] == {"upper": None, "lower": None}
    assert [w for w in s["warnings"] if "never pursued" in w] == [
        f"segment 1 (target -55 deg) was never pursued: the next segment started at the same time, "
        f"t = {seg1['start_s']:.6g} s"]
    assert not any("never pursued" in w for w in simulate("paper2010", "cooperative", "0:-25,reach:-55",
                                                          t_end_s=12.0).summary()["warnings"])


def test_a_segment_without_samples_is_shown_and_tabled_without_an_overshoot(capsys):
    """Its overshoot of None reached the terminal table's format and a sweep row's float(): both
    raised TypeError (the CLI fuzzer: a segment starting between the last sample and t_end, which
    the output grid now refuses; here a target never pursued). The table shows '-', the row NaN."""
    from smafinger.analysis.sweep_rows import metrics_row
    from smafinger.cli.show import print_run

    r = simulate("paper2010", "cooperative", "0:-25,reach:-55,3:-40", t_end_s=12.0)
    assert r.summary()["segments"][1]["overshoot_deg"] is None
    print_run(r)
    rows = [[c.strip() for c in line.split("│")[1:-1]] for line in capsys.readouterr().out.splitlines()
            if line.strip().startswith("│ ")]
    assert [row[-1] == "-" for row in rows if row[0] in "012"] == [False, True, False]
    row = metrics_row(r)
    assert math.isnan(row["seg1_overshoot_deg"]) and row["seg0_overshoot_deg"] >= 0.0


def test_an_open_loop_run_reports_no_reach_and_no_overshoot():
    """An open-loop run's one segment holds the rest position with no wire enabled: its target was
    reported reached after one step and its overshoot as 0.0 while the slider went 17.9 mm out
    (found by review); the same values became a sweep's seg0_* columns. Now None (NaN in a row)."""
    from smafinger.analysis.sweep_rows import metrics_row

    r = simulate("linear-bias-spring", "open-loop", voltage="0:0,2:0.3", drive="duty", t_end_s=6.0)
    (seg,) = r.summary()["segments"]
    assert seg["reached_s"] is None and seg["overshoot_m"] is None
    assert seg["energy_J"]["wire"] > 0 and np.ptp(r.position_m) > 0.005
    row = metrics_row(r)
    assert math.isnan(row["seg0_reached_s"]) and math.isnan(row["seg0_overshoot_m"])
    closed = simulate("linear-bias-spring", "cooperative", "0:0.004", t_end_s=6.0).summary()["segments"][0]
    assert closed["reached_s"] is not None and closed["overshoot_m"] is not None


def test_the_public_helpers_on_edge_inputs():
    """Found by an API fuzz: numpy's errors from inside, a division by zero, and an empty window
    reported as settled at once."""
    from smafinger.cycle_metrics import reduction

    t, th, none = np.linspace(0.0, 1.0, 11), np.linspace(0.0, -10.0, 11), np.array([])
    with pytest.raises(ValueError, match=r"t_off_s = 0.5 is before the first sample \(1 s\)"):
        M.openloop_metrics(t + 1.0, th, 0.5)
    with pytest.raises(ValueError, match=r"on_s\[0\] = \(5, 6\): no sample of the run \(0 to 1 s\)"):
        M.onoff_cycle_metrics(t, th, t, t, t, [(5, 6)])
    for call in (lambda: M.sample_at(none, none, 0.0), lambda: M.increase(none, none, 0.0, 1.0),
                 lambda: M.run_metrics(none, none, [], {"u": none}, {"u": none}, {"u": none})):
        with pytest.raises(ValueError, match="t has no samples"):
            call()
    assert reduction(0.0, 0.0) is None and reduction(10.0, 6.0) == pytest.approx(0.4)
    assert M.settle_time(t, th, -10.0, 5.0, 6.0) is None  # no sample in [5, 6] s: was 0.0, "at once"
    assert M.settle_time(t, th, -10.0, 0.0, 1.0) == pytest.approx(1.0)  # inside only at the last sample
    assert M.rest_time(t, np.zeros_like(t), 5.0, 6.0) is None and M.rest_time(t, np.zeros_like(t), 0.0, 1.0) == 0.0
