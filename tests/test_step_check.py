"""The step check (smafinger.step_check): a run against the same run at half its step.

Richardson's estimate on the smooth case of the convergence test (an error of known order), a
light, undamped rig the reference step does not hold (found by a random search of the rig,
docs/speed.md) flagged with its true error over the budget, the template rig within it, and the
command's default (on for the rig, off for the joint).
"""

import json
import math
import types

import numpy as np
import pytest

from smafinger.cli import main
from smafinger.engine.numerics import reference_dt
from smafinger.engine.run import make_spec, run_spec, simulate
from smafinger.parameters import get
from smafinger.step_check import ASSUMED_ORDER, check_step, checked_by_default, with_step_check
from test_engine import smooth_case

#: the rig of a random search's run 21-276 (docs/speed.md, "The linear rig"): a 2 m wire pulling
#: 2.3 g, damping ratio 0.04, full duty cut at 1.34 s; RK4 at its reference step (0.5 ms, 0.69 rad
#: of the wire-slider mode) damps the slider's ringing. No plausibility warning.
LIGHT_RIG = dict(
    wire_diameter_m=0.000388086, wire_length_m=1.98749, resistance_ohm_per_m=6.45516, eps_R=0.0144039,
    bias_spring_preload_N=2.42716, external_force_N=0.0, bias_spring_K_N_m=13.5035, A_S0_C=42.8966,
    A_F0_C=57.8086, M_S0_C=19.9691, M_F0_C=9.51525, T_amb_C=1.64332, T_init_C=1.64332,
    h0_heating_W_m2K=43.0298, h2_heating_W_m2K3=0.0, h0_cooling_W_m2K=192.81, h2_cooling_W_m2K3=0.0,
    V_H_V=15.871, V_L_V=1.52675, slider_mass_kg=0.00228185, viscous_damping_N_s_m=0.252778,
    static_friction_N=0.212982, coulomb_friction_N=0.0762727, stroke_max_m=0.0858828, stroke_min_m=-0.000204104,
    xi_init=1.0, c_A_Pa_per_C=6073650.0, c_M_Pa_per_C=13686700.0, pwm_period_s=0.001, D_A_Pa=73325100000.0,
    D_M_Pa=30472000000.0)
LIGHT_RIG_RUN = dict(strategy="open-loop", voltage="0:1.0,1.3367:0", drive="duty", t_end_s=6.2)


def _error(result, truth, name):
    e = result.signal(name) - truth.signal(name)
    return float(np.sqrt(np.mean(e ** 2))), float(np.max(np.abs(e)))


@pytest.mark.parametrize("method, low, high", [("euler", 0.8, 1.25), ("rk4", 1.5, 2.5)])
def test_estimate_against_the_true_error_on_a_smooth_case(method, low, high):
    """First order: the estimate (twice the difference) is the error; fourth order: about 2 x 16/15
    times it, the overestimate the module docstring states."""
    assert ASSUMED_ORDER == 1
    p = smooth_case()
    run = dict(strategy="open-loop", voltage="0:8:0", t_end_s=0.4, output_interval_s=0.01)
    r = simulate(p, **run, dt_s=1e-3, method=method, check_step=True)
    truth = simulate(p, **run, dt_s=1e-5, method="rk4")
    rms, worst = _error(r, truth, "theta_deg")
    chk = r.step_check
    assert chk.check_dt_s == 5e-4 and chk.factor == 2.0
    assert worst > 0 and low < chk.estimated_max / worst < high, (chk, worst)
    assert low < chk.estimated_rms / rms < high, (chk, rms)


def test_a_light_undamped_rig_is_flagged_and_is_over_the_budget():
    p = get("linear-bias-spring").replace(**LIGHT_RIG)
    spec = make_spec(p, **LIGHT_RIG_RUN)
    assert spec.method == "rk4" and spec.dt_s == reference_dt(p) == 5e-4  # the reference
    r = run_spec(spec)
    assert r.metrics["warnings"] == []  # nothing else says so
    checked = with_step_check(r)
    chk = checked.step_check
    truth = run_spec(make_spec(p, **LIGHT_RIG_RUN, dt_s=5e-5, method="rk4"))
    rms, worst = _error(r, truth, "position_m")
    assert rms > p.coordinate.accuracy_rms  # the error is over the budget...
    assert not chk.within and chk.estimated_rms >= rms  # ...and the check says so, not less
    assert [w for w in checked.metrics["warnings"] if "has not converged at its step" in w]
    assert checked.summary()["step_check"]["within"] is False
    assert r.step_check is None  # the unchecked result is left as it was


def test_the_template_rig_is_within_the_budget_and_checked_by_default():
    p = get("linear-bias-spring")
    assert checked_by_default(p) and not checked_by_default(get("paper2010"))
    assert checked_by_default(get("paper2010").replace(C_DF_heating_Nms=0.05))
    assert not checked_by_default(get("paper2010").replace(C_DF_heating_Nms=0.05), validated=True)
    assert checked_by_default(p.replace(slider_mass_kg=0.1), validated=True)  # a slider: always
    r = simulate(p, "open-loop", voltage="0:0.6,6:0,12:0.4,18:0", drive="duty", t_end_s=25.0, check_step=True)
    chk = r.step_check
    assert chk.within and 0 < chk.rms < chk.budget_rms and chk.signal == "position_m"
    assert not [w for w in r.metrics["warnings"] if "converged" in w]


def test_deterministic_and_decimated():
    r = simulate("linear-bias-spring", "open-loop", voltage="0:0.6,3:0", drive="duty", t_end_s=6.0)
    a, b = check_step(r), check_step(r)
    assert a == b
    d = check_step(r.decimated(10))  # the same samples, every tenth
    assert d.max <= a.max and d.check_dt_s == a.check_dt_s


def test_a_one_tick_step_has_no_half():
    spec = make_spec("paper2010", "cooperative", "0:-30", t_end_s=1e-6, dt_s=1e-9, output_interval_s=1e-7,
                     method="rk4", pwm="exact")
    with pytest.raises(ValueError, match="dt_s = 1e-09 s is the clock's tick"):
        check_step(run_spec(spec))


def test_simulate_command_checks_the_rig_by_default_and_the_joint_when_asked(tmp_path, capsys):
    rig = ["simulate", "--params", "linear-bias-spring", "--strategy", "open-loop", "--duty", "0:0.6,3:0",
           "--t-end", "6", "--no-progress"]
    joint = ["simulate", "--profile", "0:-30", "--t-end", "2", "--no-progress"]
    changed = joint + ["--set", "C_DF_heating_Nms=0.05"]  # a set no one validated the defaults on
    scenario = ["simulate", "--scenario", "fig11-controller-off-v1", "--no-progress"]  # as registered
    for args, checked, signal in ((rig, True, "position_m"), (rig + ["--no-check-step"], False, None),
                                  (joint, False, None), (joint + ["--check-step"], True, "theta_deg"),
                                  (changed, True, "theta_deg"), (scenario, False, None),
                                  (scenario + ["--dt", "0.001"], False, None),  # its own numerics, repeated
                                  (scenario + ["--set", "C_DF_heating_Nms=0.05"], True, "theta_deg")):
        out = tmp_path / "s.json"
        assert main([*args, "--summary", str(out)]) == 0
        doc = json.loads(out.read_text())
        assert ("step_check" in doc) == checked and ("step check:" in capsys.readouterr().out) == checked, args
        if checked:
            chk = doc["step_check"]
            assert chk["signal"] == signal and chk["check_dt_s"] == chk["dt_s"] / 2 and math.isfinite(chk["rms"]) and chk["within"] is True


def test_identify_actuator_checks_the_step_of_every_predicted_run(tmp_path):
    """`identify actuator` simulates each run at half the fit's step too: the light rig's run is
    reported as not converged, the template's is within the budget."""
    from typer.testing import CliRunner

    from smafinger.analysis import bench_synth as bs
    from smafinger.cli import app
    from smafinger.parameters.files import to_toml

    light = get("linear-bias-spring").replace(**LIGHT_RIG)
    for name, p in (("light", light), ("template", get("linear-bias-spring"))):
        (tmp_path / f"{name}.toml").write_text(to_toml(p))
        bs.write_csv(tmp_path / f"{name}.csv", bs.open_loop_run(p, LIGHT_RIG_RUN["voltage"], LIGHT_RIG_RUN["t_end_s"], seed=1))
    reports = {}
    for name in ("light", "template"):
        r = CliRunner().invoke(app, ["identify", "actuator", "--params", str(tmp_path / f"{name}.toml"), "--validate",
                                     str(tmp_path / f"{name}.csv"), "--report", str(tmp_path / f"{name}.json"),
                                     "--workers", "1", "--no-progress"])
        assert r.exit_code == 0, r.output
        reports[name] = (json.loads((tmp_path / f"{name}.json").read_text())["files"][0]["step_check"], r.output)
    light_check, light_out = reports["light"]
    assert light_check["within"] is False and "has not converged at the run's step" in light_out
    template_check, template_out = reports["template"]
    assert template_check["within"] is True and "converged" not in template_out


def test_checking_a_decimated_result_keeps_its_full_resolution_metrics():
    r = simulate("linear-bias-spring", "cooperative", "0:0.010,15:0.004", t_end_s=30.0).decimated(50)
    checked = with_step_check(r)
    before, after = r.metrics, checked.metrics
    assert {k: v for k, v in after.items() if k != "warnings"} == {k: v for k, v in before.items() if k != "warnings"}
    added = [w for w in after["warnings"] if w not in before["warnings"]]
    assert len(added) == 1 and "a closed loop can amplify" in added[0]  # the rig's closed loop: not converged
    again = with_step_check(checked)  # checked twice: one warning, not two
    assert again.metrics["warnings"] == after["warnings"]


def test_the_api_refuses_a_bad_check_step_and_a_step_with_no_half():
    with pytest.raises(TypeError, match="check_step = 'no' is not True or False"):
        simulate("paper2010", "cooperative", "0:-30", t_end_s=1.0, check_step="no")
    with pytest.raises(ValueError, match="clock's tick"):
        simulate("paper2010", "cooperative", "0:-30", t_end_s=1e-6, output_interval_s=1e-6, dt_s=1e-9, check_step=True)


def test_a_replay_keeps_the_choice_and_a_one_tick_step_is_refused_or_skipped(tmp_path, capsys):
    first, again = tmp_path / "a.json", tmp_path / "b.json"
    assert main(["simulate", "--profile", "0:-30", "--t-end", "2", "--check-step", "--summary", str(first),
                 "--no-progress"]) == 0
    assert main(["simulate", "--from", str(first), "--summary", str(again), "--no-progress"]) == 0
    a, b = (json.loads(f.read_text()) for f in (first, again))
    assert a.pop("wall_s") and b.pop("wall_s") and a == b and "step_check" in a
    tick = ["simulate", "--params", "linear-bias-spring", "--strategy", "open-loop", "--duty", "0:0.6", "--t-end",
            "1e-6", "--output-interval", "1e-6", "--dt", "1e-9", "--summary", str(tmp_path / "t.json"), "--no-progress"]
    capsys.readouterr()
    assert main(tick) == 0 and "the step was not checked" in capsys.readouterr().err
    assert main(tick[:-3] + ["--check-step", "--summary", str(tmp_path / "u.json")]) == 2
    assert not (tmp_path / "u.json").exists()


def test_the_check_under_auto_runs_on_the_engine_the_run_used():
    from smafinger.engine.interpreted import INTERPRETED_LIMIT_S, interpreted_estimate_s
    from smafinger.step_check import check_engine, half_step

    def ran(engine, t_end_s):
        spec = make_spec("linear-bias-spring", "open-loop", voltage="0:0.3", drive="duty", t_end_s=t_end_s)
        return types.SimpleNamespace(engine=engine, spec=spec)

    short, long_ = ran("interpreted", 2.0), ran("interpreted", 600.0)
    assert interpreted_estimate_s(half_step(long_.spec)) > INTERPRETED_LIMIT_S
    assert check_engine(short, "auto") == "interpreted" and check_engine(long_, "auto") is None
    assert check_engine(ran("compiled", 600.0), "auto") == "compiled"
    assert check_engine(long_, "interpreted") == "interpreted"  # asked for: as asked


def test_a_sweep_with_check_step_estimates_each_runs_error(tmp_path):
    """`[sweep] check_step = true`: the light rig's row gets its estimated error over the budget and
    the warning; the same rig well damped (damping ratio about 0.8) is within; without the key the
    columns are NaN and the run ids the same."""
    import pandas as pd

    from smafinger.analysis.sweep import SweepSpecError, parse_spec, run_sweep

    fixed = {k: v for k, v in LIGHT_RIG.items() if k != "viscous_damping_N_s_m"}
    base = {"params": "linear-bias-spring", "set": fixed, **LIGHT_RIG_RUN}
    vary = {"viscous_damping_N_s_m": {"values": [LIGHT_RIG["viscous_damping_N_s_m"], 5.0]}}
    frames = {}
    for check in (True, False):
        spec = parse_spec({"base": base, "vary": vary, "sweep": {"check_step": check}})
        run_sweep(spec, tmp_path / f"{check}.parquet", workers=1)
        frames[check] = pd.read_parquet(tmp_path / f"{check}.parquet").sort_values("point")
    on, off = frames[True], frames[False]
    assert on["run_id"].tolist() == off["run_id"].tolist() and (on["status"] == "ok").all()
    light, damped = on.iloc[0], on.iloc[1]
    assert light["step_error_rms_m"] > 5e-5 and "has not converged at its step" in light["warnings"]
    assert damped["step_error_rms_m"] < 5e-5 and damped["step_error_max_m"] < 6e-4 and not damped["warnings"]
    assert on["step_error_rms_deg"].isna().all() and off[["step_error_rms_m", "step_error_max_m"]].isna().all().all()
    with pytest.raises(SweepSpecError, match=r"\[sweep\] check_step: 'yes' is not true or false"):
        parse_spec({"base": base, "vary": vary, "sweep": {"check_step": "yes"}})


def test_a_sweep_turned_to_check_step_says_which_rows_it_did_not_check(tmp_path):
    """Run ids do not change with check_step, so a sweep run without it and then with it keeps
    its rows: the report and the metadata say how many were not checked (found by review); a
    one-tick step is refused in the check pass."""
    import pyarrow.parquet as pq

    from smafinger.analysis.sweep import SweepSpecError, parse_spec, run_sweep

    data = {"base": {"params": "linear-bias-spring", "strategy": "open-loop", "voltage": "0:0.6,1:0",
                     "drive": "duty", "t_end_s": 2.0}, "vary": {"slider_mass_kg": {"values": [0.05, 0.1, 0.2]}}}
    out = tmp_path / "s.parquet"
    assert run_sweep(parse_spec(data), out, workers=1).unchecked_total == 0
    rep = run_sweep(parse_spec({**data, "sweep": {"check_step": True}}), out, workers=1)
    assert rep.resumed == 3 and rep.unchecked_total == 3
    meta = json.loads(pq.read_schema(out).metadata[b"smafinger.sweep"])
    assert meta["spec"]["check_step"] is True and meta["step_unchecked"] == 3
    fresh = run_sweep(parse_spec({**data, "sweep": {"check_step": True}}), tmp_path / "f.parquet", workers=1)
    assert fresh.unchecked_total == 0
    tick = {"base": {**data["base"], "t_end_s": 1e-5, "output_interval_s": 1e-6},
            "vary": {"dt_s": {"values": [2e-9, 1e-9]}}, "sweep": {"check_step": True}}
    with pytest.raises(SweepSpecError, match=r"point 1 \(dt_s = 1e-09\).*clock's tick"):
        run_sweep(parse_spec(tick), tmp_path / "t.parquet", workers=1)


def test_identify_actuator_names_why_a_runs_check_failed(tmp_path, monkeypatch):
    """A run at half the step that fails is named with its reason, in the warning and in the
    report's files[].step_check and step_notes, with or without a fit (found by review)."""
    import dataclasses

    from smafinger.analysis import actuator_report as ar
    from smafinger.analysis import bench_synth as bs
    from smafinger.analysis.bench_runs import load_open_loop
    from smafinger.engine.batch import make_pool

    p = get("linear-bias-spring")
    bs.write_csv(tmp_path / "a.csv", bs.open_loop_run(p, "0:0,0.2:0.5,2:0", 3.0, seed=1))
    run = load_open_loop(tmp_path / "a.csv", None, "validate", p)
    monkeypatch.setattr(ar, "half_step", lambda spec: dataclasses.replace(spec, dt_s=2 * spec.t_end_s))
    with make_pool(1) as pool:
        (pr,) = ar.predict_runs([run], p, pool)
    assert pr.model is not None and pr.step is None and "longer than t_end_s" in pr.step_error
    (note,) = ar.step_notes([pr], p, fitted=False)
    assert "a.csv (validate): ValueError" in note and "longer than t_end_s" in note
    assert ar.files_report([pr], p)[0]["step_check"] == {"error": pr.step_error}


def test_a_pwm_far_faster_than_the_step_is_not_judged():
    """A 10 kHz PWM on the template rig: its edges set the sub-steps whatever the step (66,000 of
    them at half the step against 63,000), so the estimate would be 21x a difference that says
    little: the check does not judge, says so in its line, and warns of nothing."""
    from smafinger.step_check import MIN_REFINEMENT

    p = get("linear-bias-spring")
    kw = dict(voltage="0:0.6,3:0", drive="duty", t_end_s=6.0, check_step=True)
    fast = simulate(p.replace(pwm_period_s=1e-4), "open-loop", **kw)
    chk = fast.step_check
    assert chk.refinement < MIN_REFINEMENT and not chk.judged and chk.within is None
    assert "not judged" in chk.describe() and math.isnan(chk.estimated_rms) and fast.metrics["warnings"] == []
    d = fast.summary()["step_check"]  # strict JSON: null, not NaN (found by an API fuzz)
    assert (d["judged"], d["factor"], d["estimated_rms"], d["estimated_max"], d["within"]) == (False,) + (None,) * 4
    json.dumps(fast.summary(), allow_nan=False)
    assert chk.to_dict()["judged"] is False
    slow = simulate(p, "open-loop", **kw).step_check  # the template's 1 kHz: judged
    assert slow.judged and slow.refinement > 1.5 and slow.within


def test_the_check_keeps_the_runs_output_interval_where_twice_the_samples_are_over_the_memory_limit(monkeypatch):
    """Halving the output interval doubles the samples: a run just within the memory limit made
    its check raise an internal error after the run (found by review); it now keeps the run's interval."""
    import smafinger.engine.run as engine_run

    r = simulate("linear-bias-spring", "open-loop", voltage="0:0.6,3:0", drive="duty", t_end_s=6.0)
    monkeypatch.setattr(engine_run, "memory_limit_bytes", lambda: 2 * 8 * 9000 * 21)  # 6,001 samples pass, 12,001 not
    chk = with_step_check(r).step_check
    assert chk.check_dt_s == 5e-4 and chk.judged and chk.within


def test_a_sweep_row_the_check_did_not_judge_is_checked_not_unchecked(tmp_path):
    """A 10 kHz PWM row: checked, not judged (NaN errors, its refinement recorded); it was counted
    as a row made before check_step was on (found by review)."""
    import pandas as pd

    from smafinger.analysis.sweep import parse_spec, run_sweep

    data = {"base": {"params": "linear-bias-spring", "strategy": "open-loop", "voltage": "0:0.6,3:0", "drive": "duty",
                     "t_end_s": 6.0}, "vary": {"pwm_period_s": {"values": [1e-3, 1e-4]}}, "sweep": {"check_step": True}}
    rep = run_sweep(parse_spec(data), tmp_path / "s.parquet", workers=1)
    df = pd.read_parquet(tmp_path / "s.parquet").sort_values("point")
    assert rep.unchecked_total == 0 and df["step_refinement"].notna().all()
    assert df["step_error_rms_m"].notna().tolist() == [True, False] and df["step_refinement"].iloc[1] < 1.05


def test_identify_joint_warns_when_the_fitted_damping_is_at_its_steps_stability_limit():
    """The joint fit runs every candidate at RK4, 1 ms: beyond C_DF / I = 2,785 1/s candidates blew
    up and were scored as misses, so curves made with C_DF_cooling 0.2 were fitted to 0.1355
    +- 9e-8 with no warning (found by review). A fitted damping at 90 % of that limit or more is warned."""
    from smafinger.analysis.joint_phase import _stability_warnings

    p = get("paper2010")
    assert _stability_warnings("cooling", p) == []  # 1,844 1/s: 66 % of the limit
    (w,) = _stability_warnings("cooling", p.replace(C_DF_cooling_Nms=0.1355))
    assert w.startswith("cooling: the fitted damping (C_DF / I = 2777 1/s) is at 100% of what rk4 holds")


def test_a_sweep_rows_blow_up_says_what_to_change(tmp_path):
    """A point damped beyond what RK4 at its step holds blows up: its error says which parameter
    and which step, as simulate's does (the sweep's error column had only the state; found by review)."""
    import pandas as pd

    from smafinger.analysis.sweep import parse_spec, run_sweep

    data = {"base": {"params": "paper2010-table2", "strategy": "open-loop", "voltage": "0:8:0", "t_end_s": 8.0,
                     "method": "euler"}, "vary": {"inertia_kg_m2": {"values": [4.88e-5, 1e-9]}}}
    run_sweep(parse_spec(data), tmp_path / "s.parquet", workers=1)
    df = pd.read_parquet(tmp_path / "s.parquet").sort_values("point")
    assert df["status"].tolist() == ["ok", "error"]
    assert "numerical blow-up" in df["error"].iloc[1] and "check inertia_kg_m2 = 1e-09" in df["error"].iloc[1]
    assert 'use a smaller dt_s or method = "exponential"' in df["error"].iloc[1]  # its file's keys, not --dt


def test_a_compact_batch_result_is_refused_by_name():
    """A batch's CompactResult keeps decimated float32 signals and no sub-step count: the check
    refuses it with a TypeError naming its type (it raised AttributeError on a missing field)."""
    from smafinger.engine.batch import Compact

    spec = make_spec("linear-bias-spring", "open-loop", voltage="0:0.5,1:0", t_end_s=2.0)
    compact = Compact(every=10)(run_spec(spec))
    for call in (check_step, with_step_check):
        with pytest.raises(TypeError, match="CompactResult"):
            call(compact)


def test_a_batch_checks_its_runs_in_the_workers_when_asked():
    """Compact(check_step=True) checks each run where it ran: the compact summary holds the same
    check as the run checked alone, and the warning with it."""
    from smafinger.engine.batch import Compact, run_batch

    light = get("linear-bias-spring").replace(**LIGHT_RIG)
    specs = [make_spec(light, **LIGHT_RIG_RUN), make_spec("paper2010", "cooperative", "0:-30", t_end_s=2.0)]
    out = run_batch(specs, workers=1, reduce=Compact(every=10, check_step=True))
    for spec, compact in zip(specs, out):
        alone = with_step_check(run_spec(spec))
        assert compact.summary["step_check"] == alone.summary()["step_check"]
        assert compact.summary["warnings"] == alone.summary()["warnings"]
    assert [c.summary["step_check"]["within"] for c in out] == [False, True]  # the light rig's warning travels
    assert any("step" in w for w in out[0].summary["warnings"])
    assert "step_check" not in run_batch(specs[:1], workers=1, reduce=Compact(every=10))[0].summary
    with pytest.raises(TypeError, match="check_step"):
        Compact(check_step="yes")


def test_a_failed_check_in_python_says_what_skips_it_there(monkeypatch):
    """The run at half the step stopping: simulate(check_step=True) and Compact(check_step=True)
    name their own argument, not the command's --no-check-step (found by review)."""
    import smafinger.engine.run as engine_run
    from smafinger.engine.batch import Compact

    real = engine_run.run_spec
    spec = make_spec("paper2010", "cooperative", "0:-30", t_end_s=1.0)

    def stops_at_half_step(s, *args, **kwargs):
        if s.dt_s < spec.dt_s:
            raise engine_run.SimulationError("numerical blow-up at t = 0.5 s (on purpose)")
        return real(s, *args, **kwargs)

    monkeypatch.setattr(engine_run, "run_spec", stops_at_half_step)
    for call in (lambda: Compact(check_step=True)(real(spec)),
                 lambda: simulate("paper2010", "cooperative", "0:-30", t_end_s=1.0, check_step=True)):
        with pytest.raises(engine_run.SimulationError, match=r"stopped \(check_step=False skips the check\)"):
            call()
