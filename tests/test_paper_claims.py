"""The paper's qualitative claims, asserted on the outputs of the named scenarios.

Every scenario runs once (module fixture, about 5 s in all once numba's cache is warm) at
the scenarios' own settings (1 ms step and output). A claim the model does not reproduce is
asserted as the paper states it and marked ``xfail(strict=True)`` with the measured values:
it is reported, not bent, and the marker has to go if the model ever reproduces it.
"""

from __future__ import annotations

import re
from types import SimpleNamespace

import numpy as np
import pytest

from smafinger import scenarios
from smafinger.engine.run import run_spec
from smafinger.reproduce import cooling_phase_metrics, cycle_time, openloop_metrics, segment_metrics


@pytest.fixture(scope="module")
def runs():
    return {name: run_spec(scenarios.get(name).spec()) for name in scenarios.names()}


def _sweep(runs, group, wire):
    sel = [s for s in scenarios.all_scenarios() if s.group == group and s.meta.get("wire") == wire]
    sel.sort(key=lambda s: s.meta["value"])
    return [(s.meta["value"], openloop_metrics(runs[s.name].t, runs[s.name].theta_deg, s.meta["t_off_s"]))
            for s in sel]


def _increasing(xs):
    return all(b > a for a, b in zip(xs, xs[1:]))


# ---- registry -----------------------------------------------------------------------------
def test_registry_names_are_versioned_and_cite_a_figure():
    names = scenarios.names()
    assert len(names) == len(set(names)) >= 40
    for n in names:
        s = scenarios.get(n)
        assert re.search(r"-v[0-9]+$", n) and s.name == n, n
        assert s.figure and s.description
    for required in ("fig8-h0-60-upper-v1", "fig11-controller-off-v1", "fig11-controller-off-v2", "fig15-independent-v1",
                     "fig15-cooperative-v1", "authors2020-profile1-v1", "authors2020-profile2-v1"):
        assert required in names


def test_unknown_scenario_names_the_known_ones():
    with pytest.raises(ValueError, match="unknown scenario 'fig99-v1'.*fig15-cooperative-v1"):
        scenarios.get("fig99-v1")


def test_spec_applies_overrides_after_the_scenarios_own():
    s = scenarios.get("fig8-h0-60-upper-v1")
    spec = s.spec(overrides=["M_SF_Nm=0.02"], dt_s=5e-4, output_interval_s=1e-2, tol_deg=0.2, hold_s=1.0)
    assert spec.params.h0_heating_W_m2K == 60.0 and spec.params.h0_cooling_W_m2K == 60.0
    assert spec.params.M_SF_Nm == 0.02
    assert (spec.dt_s, spec.output_interval_s, spec.tol_deg, spec.hold_s) == (5e-4, 1e-2, 0.2, 1.0)
    assert scenarios.get("fig11-controller-off-v1").spec().params.controller_in_cooling is False
    assert scenarios.get("fig11-controller-on-v1").spec().params.controller_update_s == 0.01


# ---- Sec. 2.6: the interlock ----------------------------------------------------------------
@pytest.mark.parametrize("name", scenarios.names())
def test_zero_interlock_violations(runs, name):
    assert runs[name].interlock_violations == 0


# ---- Fig. 7: larger C_DF -> slower motion -------------------------------------------------
@pytest.mark.parametrize("wire", ["upper", "lower"])
def test_fig7_larger_cdf_slows_the_motion(runs, wire):
    sweep = _sweep(runs, "fig07-cdf", wire)
    assert len(sweep) == 3
    rise = [m["rise90_s"] for _, m in sweep]
    back = [m["return90_s"] for _, m in sweep]
    assert _increasing(rise), rise  # heating phase: slower to its maximum range
    assert _increasing(back), back  # cooling phase: slower back
    # C_DF changes the speed, not where the joint gets to
    ranges = [m["range_deg"] for _, m in sweep]
    assert max(ranges) - min(ranges) < 0.1 * max(ranges)


# ---- Fig. 8: lower h0 -> larger range and earlier start ---------------------------------------
@pytest.mark.parametrize("wire", ["upper", "lower"])
def test_fig8_lower_h0_larger_range_and_earlier_start(runs, wire):
    sweep = _sweep(runs, "fig08-h0", wire)
    assert [v for v, _ in sweep] == [60.0, 65.0, 70.0]
    ranges = [m["range_deg"] for _, m in sweep]
    starts = [m["start_s"] for _, m in sweep]
    assert all(s is not None for s in starts)
    assert _increasing([-r for r in ranges]), ranges  # h0 60 > 65 > 70 in range
    assert _increasing(starts), starts  # h0 60 starts first
    # every variant had reached its maximum range before the voltage was removed
    assert all(m["still_moving_deg_s"] < 0.05 for _, m in sweep)


# ---- Fig. 11: controller off in the cooling phase -> faster return, larger overshoot ------------
def test_fig11_controller_off_cools_faster_but_overshoots_more(runs):
    """v2 reading: the cooling phase is the joint past -30 deg during the extension (Sec. 2.6),
    wire and surroundings at the authors' 60 degC."""
    on = cooling_phase_metrics(runs["fig11-controller-on-v2"], -30.0)
    off = cooling_phase_metrics(runs["fig11-controller-off-v2"], -30.0)
    assert on["cooling_s"] is not None and off["cooling_s"] is not None
    # "a relatively faster cooling": shorter, and the wire's temperature falls faster
    assert off["cooling_s"] < 0.8 * on["cooling_s"], (on, off)
    assert off["cooling_rate_C_s"] > 1.5 * on["cooling_rate_C_s"], (on, off)
    # "a tendency to overshoot the desired joint position": falls further below -30 deg
    assert off["overshoot_after_deg"] > max(2.0 * on["overshoot_after_deg"], 0.02), (on, off)


def test_cooling_phase_metrics_on_a_known_signal():
    t = np.arange(0.0, 10.0, 0.01)
    theta = np.where(t < 2.0, -40.0 + 5.0 * t, -30.0 + 0.2 * np.sin(np.pi * (t - 2.0) / 3.0))
    T = 90.0 - 2.0 * t
    m = cooling_phase_metrics(SimpleNamespace(t=t, theta_deg=theta, T_upper_C=T), -30.0)
    assert m["cooling_start_s"] == pytest.approx(2.01)
    assert m["cooling_s"] == pytest.approx(3.0, abs=0.011)
    assert m["cooling_rate_C_s"] == pytest.approx(2.0)
    assert m["peak_past_deg"] == pytest.approx(0.2, abs=1e-3)
    assert m["overshoot_after_deg"] == pytest.approx(0.2, abs=1e-3)
    flat = cooling_phase_metrics(SimpleNamespace(t=t, theta_deg=np.full_like(t, -35.0), T_upper_C=T), -30.0)
    assert flat["cooling_s"] is None and flat["peak_past_deg"] == 0.0


@pytest.mark.xfail(strict=True, reason=(
    "v1 reading (cooling phase = the return to -40 deg, 23 degC) not reproduced: return to -40 deg 5.51 s (on) vs 5.58 s (off), overshoot 0.030 deg both. "
    "With K_P = K_V and the integral reset at the new target the PID output stays negative during "
    "the return, so 'on' applies 0 V too; the -30 deg target is approached without overshoot. "
    "See report.md (Fig. 11)."))
def test_fig11_v1_controller_off_returns_faster_but_overshoots_more(runs):
    on = runs["fig11-controller-on-v1"]
    off = runs["fig11-controller-off-v1"]
    r_on, r_off = segment_metrics(on, 1), segment_metrics(off, 1)
    ov_on = max(s["overshoot_deg"] for s in on.metrics["segments"])
    ov_off = max(s["overshoot_deg"] for s in off.metrics["segments"])
    assert r_on["reached_s"] is not None and r_off["reached_s"] is not None
    assert r_off["reached_s"] < r_on["reached_s"]
    assert ov_off > ov_on


# ---- Fig. 13: the antagonist shortens the return ------------------------------------------------
@pytest.mark.parametrize("kind", ["extension", "flexion"])
def test_fig13_cooperative_return_is_faster(runs, kind):
    case1 = segment_metrics(runs[f"fig13-{kind}-case1-v1"], 1)["reached_s"]
    case2 = segment_metrics(runs[f"fig13-{kind}-case2-v1"], 1)["reached_s"]
    assert case1 is not None and case2 is not None
    assert case2 < case1


# ---- Fig. 15: co-operative full cycle 15-40 % shorter -------------------------------------------
def test_fig15_cooperative_cycle_shorter_by_15_to_40_percent(runs):
    ind_run, coop_run = runs["fig15-independent-v1"], runs["fig15-cooperative-v1"]
    ind = cycle_time(ind_run.summary(), ind_run.spec)
    coop = cycle_time(coop_run.summary(), coop_run.spec)
    assert ind is not None and coop is not None
    # targets issued on reach: the cycle time is the sum of the segments' reached_s
    assert ind == pytest.approx(sum(s["reached_s"] for s in ind_run.metrics["segments"]), abs=1e-6)
    assert coop == pytest.approx(sum(s["reached_s"] for s in coop_run.metrics["segments"]), abs=1e-6)
    reduction = (ind - coop) / ind
    assert 0.15 <= reduction <= 0.40, (ind, coop, reduction)


def test_fig15_cycles_visit_every_target(runs):
    for name in ("fig15-independent-v1", "fig15-cooperative-v1",
                 "fig15-independent-scheduled-v1", "fig15-cooperative-scheduled-v1"):
        segs = runs[name].metrics["segments"]
        assert [s["target_deg"] for s in segs][-1] == -40.0
        assert all(s["reached_s"] is not None for s in segs), name
