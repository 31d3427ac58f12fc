"""Issue 13 at the API: the clock's range, the output size, argument types (make_spec)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from smafinger import simulate
from smafinger.engine import run as engine_run
from smafinger.engine.clock import MAX_S, MAX_TICKS, TICK_S, ticks_array, to_ticks
from smafinger.engine.run import make_spec
from smafinger.engine.signals import MECHANISM_FIELDS, WIRE_FIELDS


# ---- the clock -------------------------------------------------------------------------------
@pytest.mark.parametrize("value", [1e10, 1e308, MAX_S * 1.0000001, 9.3e9])
def test_times_beyond_the_clock_are_refused_not_wrapped(value):
    with pytest.raises(ValueError, match=r"t_end_s = .* s is beyond the clock's range"):
        to_ticks("t_end_s", value)
    with pytest.raises(ValueError, match=r"voltage start \[1\] = .* beyond the clock's range"):
        ticks_array("voltage start", np.array([0.0, value]))


@pytest.mark.parametrize("kw", [{"dt_s": 1e-300}, {"output_interval_s": 1e-300}, {"dt_s": 4e-10}])
def test_times_below_the_clocks_tick_are_refused(kw):
    """A positive time under half a nanosecond rounded to 0 ticks and passed: --dt 1e-300 hung the
    kernel (0 s steps), --output-interval 1e-300 divided by zero (found by review)."""
    name = next(iter(kw))
    with pytest.raises(ValueError, match=rf"{name} = .* s is shorter than the clock's tick, 1 ns"):
        make_spec("paper2010", "cooperative", "0:-25", t_end_s=1.0, **kw)


@given(st.integers(0, MAX_TICKS))
@settings(max_examples=300, deadline=None)
def test_every_whole_nanosecond_in_range_is_held_without_overflow(k):
    t = k * TICK_S
    ticks = ticks_array("t", np.array([0.0, t]))
    assert ticks.dtype == np.int64 and 0 <= ticks[1] <= MAX_TICKS
    assert abs(int(ticks[1]) - k) <= 1 + 1e-6 * k  # float seconds hold k to about 16 digits
    assert to_ticks("t", t, allow_zero=True) == ticks[1]


def test_a_step_after_the_clock_range_no_longer_drops_the_program():
    """The silent wrong answer of issue 13: a far step wrapped to a negative time and the 8 V
    step was dropped (0 J, 23 degC, exit 0)."""
    with pytest.raises(ValueError, match="beyond the clock's range"):
        make_spec("paper2010", "open-loop", None, "0:8:0,1e10:0:0", t_end_s=1.0)
    r = simulate("paper2010", "open-loop", voltage="0:8:0,1e9:0:0", t_end_s=1.0)  # in range: kept
    assert r.metrics["energy_J"]["upper"] > 1.0


@pytest.mark.parametrize("kw", [dict(t_end_s=1e308), dict(dt_s=1e308), dict(hold_s=1e308),
                                dict(output_interval_s=1e308), dict(profile="0:-25,1e10:-40")])
def test_huge_times_are_value_errors_not_overflow(kw):
    args = dict(params="paper2010", strategy="cooperative", profile="0:-25", t_end_s=1.0)
    args.update(kw)
    with pytest.raises(ValueError):
        make_spec(**args)


# ---- the output size -------------------------------------------------------------------------
#: the joint's recorded signals: the mechanism's and each of its two wires' (engine/signals.py)
JOINT_SIGNALS = len(MECHANISM_FIELDS) + 2 * len(WIRE_FIELDS)


@pytest.mark.parametrize("kw", [dict(t_end_s=1e6), dict(t_end_s=1.0, output_interval_s=1e-9)])
def test_runs_too_large_for_memory_are_refused_with_the_size(kw):
    n = JOINT_SIGNALS
    gib = 2 * 8 * 1_000_000_001 * n / 2**30
    with pytest.raises(ValueError, match=rf"1,000,000,001 samples x {n} signals, about {gib:,.1f} GiB .* more than the"):
        make_spec("paper2010", "cooperative", "0:-25", **kw)


def test_the_limit_is_half_the_memory_and_is_applied(monkeypatch):
    assert engine_run.memory_limit_bytes() > 0
    spec = make_spec("paper2010", "cooperative", "0:-25", t_end_s=1.0)
    args = engine_run.kernel_args(spec)
    samples, signals, need = engine_run.output_size(spec, args["run"])
    assert (samples, signals) == (1001, JOINT_SIGNALS) and need == 2 * 8 * 1001 * JOINT_SIGNALS
    monkeypatch.setattr(engine_run, "memory_limit_bytes", lambda: need - 1)
    with pytest.raises(ValueError, match="GiB allowed"):
        make_spec("paper2010", "cooperative", "0:-25", t_end_s=1.0)
    monkeypatch.setattr(engine_run, "memory_limit_bytes", lambda: need)
    make_spec("paper2010", "cooperative", "0:-25", t_end_s=1.0)


@pytest.mark.parametrize("t_end_s, interval_s", [(10.0, 3.0), (14.0, 0.0015), (1.0, 0.3)])
def test_an_output_grid_that_misses_the_end_is_refused(t_end_s, interval_s):
    """The totals and the last segment are read at the last sample: 3 s samples over 10 s gave the
    energy at 9 s as the run's (42.2 J against 52.7 J; found by review). Refused, the message
    naming both values and the end times that would do."""
    with pytest.raises(ValueError) as info:
        make_spec("linear-bias-spring", "open-loop", voltage="0:0,0.5:0.3", drive="duty", t_end_s=t_end_s,
                  output_interval_s=interval_s)
    msg = str(info.value)
    assert f"t_end_s = {t_end_s!r}" in msg and f"output_interval_s = {interval_s!r}" in msg and "\n" not in msg
    below = float(msg.split("t_end_s = ")[-1].split(" or ")[0])
    above = float(msg.split(" or ")[-1].split(" would")[0])
    for end in (below, above):
        assert len(make_spec("paper2010", "cooperative", "0:-25", t_end_s=end,
                             output_interval_s=interval_s).profile.segments) == 1
        assert end == pytest.approx(round(end / interval_s) * interval_s) and abs(end - t_end_s) < interval_s


# ---- argument types --------------------------------------------------------------------------
@pytest.mark.parametrize("kw, message", [
    (dict(profile=[(0, -25)]), "profile = [(0, -25)] is not a profile text"),
    (dict(tol_deg="0.5"), "tol_deg = '0.5' is not a number"),
    (dict(t_end_s=True), "t_end_s = True is not a number"),
    (dict(dt_s="1e-3"), "dt_s = '1e-3' is not a number"),
    (dict(hold_s=np.bool_(True)), "hold_s = "),
    (dict(strategy=3), "strategy = 3 is not one of"),
    (dict(method=4), "method = 4 is not one of"),
    (dict(params=42), "params = 42 is not a set's name"),
    (dict(independent_wait="yes"), "independent_wait = 'yes' is not True or False"),
])
def test_wrong_types_are_one_line_type_errors_naming_the_argument(kw, message):
    args = dict(profile="0:-25", t_end_s=1.0)
    args.update(kw)
    with pytest.raises(TypeError) as info:
        simulate(**args)
    assert message in str(info.value) and "\n" not in str(info.value)


def test_numpy_numbers_are_accepted():
    r = simulate(profile="0:-25", t_end_s=np.float64(0.5), dt_s=np.float32(1e-3).item(), tol_deg=np.int64(1))
    assert math.isclose(r.t[-1], 0.5)


def test_whole_numbers_as_parameter_values_run(tmp_path):
    """``V_H_V = 6`` in a parameter file is an int: the set stores it as a float (an int field
    made the compiled records of another type, and numba failed with NotImplementedError)."""
    from smafinger.parameters import get, load_toml

    p = get("paper2010").replace(V_H_V=6, M_SF_Nm=0)
    assert type(p.V_H_V) is float and type(p.M_SF_Nm) is float and p == get("paper2010").replace(V_H_V=6.0, M_SF_Nm=0.0)
    (tmp_path / "p.toml").write_text('base = "paper2010"\nV_H_V = 6\n')
    r = simulate(load_toml(tmp_path / "p.toml"), "open-loop", voltage="0:6:0", t_end_s=0.5)
    assert r.metrics["energy_J"]["upper"] > 0


@pytest.mark.parametrize("profile, t_end, every", [("0:-20,0.25:-20,0.375:-20", 1.0, 0.5)])  # between samples
def test_segments_without_an_output_sample_have_no_peaks_instead_of_crashing(profile, t_end, every):
    """Found by the long fuzz: a segment shorter than the output interval made the metrics
    take the maximum of nothing (or index past the last sample, which no longer happens: the
    output grid ends at t_end, test_an_output_grid_that_misses_the_end_is_refused)."""
    r = simulate("paper2010", "independent", profile, t_end_s=t_end, output_interval_s=every)
    empty = [s for s in r.metrics["segments"] if s["peak_temperature_C"]["upper"] is None]
    assert empty and all(s["energy_J"] == {"upper": None, "lower": None} for s in empty)
    full = [s for s in r.metrics["segments"] if s not in empty]
    assert all(isinstance(s["peak_temperature_C"]["upper"], float) for s in full)


@pytest.mark.parametrize("params, kw, message", [
    ("linear-bias-spring", dict(profile="0:0.01", tol_deg=5.0), "tol_deg = 5.0 does not apply to linear-bias-spring"),
    ("paper2010", dict(profile="0:-25", tol_m=1e-3), "tol_m = 0.001 does not apply to paper2010"),
])
def test_a_tolerance_in_the_other_mechanisms_unit_is_refused(params, kw, message):
    """``--tol-deg 5`` on the linear rig ran with its 0.5 mm and no word (found by review)."""
    with pytest.raises(ValueError, match=message):
        make_spec(params, "cooperative", t_end_s=1.0, **kw)
    unit = "tol_m" if "tol_deg" in kw else "tol_deg"
    assert make_spec(params, "cooperative", t_end_s=1.0, profile=kw["profile"], **{unit: 1e-3}).tolerance == 1e-3
