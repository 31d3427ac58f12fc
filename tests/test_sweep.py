"""Parametric sweeps: spec parsing, sampling, run ids, tables, resume, CLI."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from hypothesis import given, settings, strategies as st
import pandas as pd
import pytest

from smafinger.analysis import sweep as sw
from smafinger.analysis.sweep import (SweepInterrupted, SweepSizeError, SweepSpecError, load_spec, parse_spec,
                                     run_sweep)
from smafinger.analysis.sweep_spec import canonical_run
from smafinger.analysis.sweep_store import traces_interval

ROOT = Path(__file__).resolve().parents[1]
FIG8 = ROOT / "examples" / "sweep-fig8.toml"
SRC = Path(sw.__file__).resolve().parents[2]


def _spec(vary: str, sweep: str = "", base: str | None = None, t_end: float = 2.0) -> str:
    base = base if base is not None else (
        f'params = "paper2010-table2"\nstrategy = "open-loop"\nvoltage = "0:8:0,1:0:0"\nt_end_s = {t_end}\n')
    return f"[base]\n{base}\n[sweep]\n{sweep}\n{vary}\n"


def _write(tmp_path: Path, text: str, name: str = "spec.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


SMALL = _spec('[vary.h0]\nfields = ["h0_heating_W_m2K", "h0_cooling_W_m2K"]\nvalues = [60.0, 70.0]\n'
              '[vary]\nC_DF_heating_Nms = [0.02, 0.03, 0.04]\n')


def _frame(path: Path) -> pd.DataFrame:
    return pd.read_parquet(path).drop(columns=["wall_s"])


# ---- spec ----------------------------------------------------------------------------
def test_fig8_example_spec():
    spec = load_spec(FIG8)
    runs = spec.runs()
    assert len(runs) >= 200
    assert len({r.run_id for r in runs}) == len(runs)
    p = runs[0].spec.params
    assert p.name == "paper2010-table2"
    assert p.h0_heating_W_m2K == p.h0_cooling_W_m2K == 60.0  # tied names set both fields
    assert p.h2_heating_W_m2K3 == p.h2_cooling_W_m2K3 == 5e-4
    assert runs[-1].spec.params.h0_cooling_W_m2K == 70.0
    assert p.friction_sticking == "initial-only"  # Sec. 3.1: stick-slip neglected
    assert runs[0].spec.strategy == "open-loop" and runs[0].spec.t_end_s == 20.0
    # stable across reloads
    assert [r.run_id for r in load_spec(FIG8).runs()] == [r.run_id for r in runs]


def test_grid_list_and_run_ids(tmp_path):
    grid = load_spec(_write(tmp_path, SMALL))
    pts = grid.points()
    assert pts[:4] == [{"h0": 60.0, "C_DF_heating_Nms": 0.02}, {"h0": 60.0, "C_DF_heating_Nms": 0.03},
                       {"h0": 60.0, "C_DF_heating_Nms": 0.04}, {"h0": 70.0, "C_DF_heating_Nms": 0.02}]
    lst = load_spec(_write(tmp_path, SMALL.replace("[sweep]\n", '[sweep]\nmode = "list"\n')
                           .replace("[0.02, 0.03, 0.04]", "[0.02, 0.03]"), "l.toml"))
    assert lst.points() == [{"h0": 60.0, "C_DF_heating_Nms": 0.02}, {"h0": 70.0, "C_DF_heating_Nms": 0.03}]
    ids = [r.run_id for r in grid.runs()]
    assert len(set(ids)) == 6 and all(len(i) == 16 for i in ids)
    # the same run in another spec has the same id
    assert [r.run_id for r in lst.runs()] == [ids[0], ids[4]]
    lin = parse_spec({"base": {"t_end_s": 1.0, "profile": "0:-30"},
                      "vary": {"M_SF_Nm": {"start": 1e-3, "stop": 1e-1, "num": 3, "log": True}}})
    assert np.allclose([p["M_SF_Nm"] for p in lin.points()], [1e-3, 1e-2, 1e-1])


def test_the_pwm_model_is_a_run_setting_with_its_own_run_id():
    """A sweep may set or vary ``pwm`` (the long-step settings need ``averaged``); the default
    leaves the canonical spec, and so the run ids of earlier sweeps, as they were."""
    spec = parse_spec({"base": {"t_end_s": 1.0, "profile": "0:-30", "method": "exponential", "dt_s": 0.005},
                       "vary": {"pwm": {"values": ["exact", "averaged"]}}})
    exact, averaged = spec.runs()
    assert exact.spec.pwm == "exact" and averaged.spec.pwm == "averaged"
    assert exact.run_id != averaged.run_id
    assert "pwm" not in canonical_run(exact.spec) and canonical_run(averaged.spec)["pwm"] == "averaged"
    with pytest.raises(SweepSpecError, match="pwm"):
        parse_spec({"base": {"t_end_s": 1.0, "profile": "0:-30", "pwm": "smooth"},
                    "vary": {"tol_deg": {"values": [0.5]}}}).runs()


def test_a_rigs_duty_program_and_tolerance_are_run_settings_with_their_own_run_ids():
    """A linear rig's sweep may give its program as a duty (``drive``) and set or vary its
    tolerance in metres (``tol_m``): both were refused, while a tol_deg on the rig was refused
    with 'give tol_m' (found by review). Their defaults leave the canonical spec, and so the run
    ids of earlier sweeps, as they were."""
    base = {"params": "linear-bias-spring", "strategy": "open-loop", "voltage": "0:0.6,3:0", "t_end_s": 1.0}
    duty, volts = parse_spec({"base": {**base, "drive": "duty"}, "vary": {"tol_m": {"values": [5e-4]}}}).runs()[0], \
        parse_spec({"base": base, "vary": {"tol_m": {"values": [5e-4]}}}).runs()[0]
    assert duty.spec.voltage.kind == "duty" and canonical_run(duty.spec)["drive"] == "duty"
    assert "drive" not in canonical_run(volts.spec) and duty.run_id != volts.run_id
    closed = parse_spec({"base": {"params": "linear-bias-spring", "profile": "0:0.01", "t_end_s": 1.0},
                         "vary": {"tol_m": {"values": [1e-4, 5e-4]}}}).runs()
    assert [r.spec.tol_m for r in closed] == [1e-4, 5e-4] and closed[0].run_id != closed[1].run_id
    assert canonical_run(closed[0].spec)["tol_m"] == 1e-4 and "tol_m" not in canonical_run(closed[1].spec)


def test_each_row_records_the_numerics_its_run_used(tmp_path):
    """A point's varied values can change its default numerics (engine.numerics): the rows say
    which each run used, and an explicit dt_s gives rk4 with exact PWM (the reference's others)."""
    spec = parse_spec({"base": {"profile": "0:-30", "t_end_s": 0.5},
                       "vary": {"pwm_period_s": {"values": [0.001, 0.01]}, "dt_s": {"values": [0.001, 0.002]}},
                       "sweep": {"mode": "list"}})
    run_sweep(spec, tmp_path / "n.parquet", workers=1)
    df = pd.read_parquet(tmp_path / "n.parquet").sort_values("point")
    assert df["run_method"].tolist() == ["rk4", "rk4"] and df["run_pwm"].tolist() == ["exact", "exact"]
    assert df["run_dt_s"].tolist() == [0.001, 0.002]
    spec = parse_spec({"base": {"profile": "0:-30", "t_end_s": 0.5},
                       "vary": {"pwm_period_s": {"values": [0.001, 0.01]}}})
    run_sweep(spec, tmp_path / "p.parquet", workers=1)
    df = pd.read_parquet(tmp_path / "p.parquet").sort_values("point")
    # a 10 ms PWM period is longer than the long step: that point gets the edge step (the PWM resolved)
    assert list(zip(df["run_method"], df["run_dt_s"], df["run_pwm"])) == [("exponential", 0.005, "averaged"),
                                                                         ("exponential", 0.005, "exact")]


def test_random_and_lhs_sampling_seeded():
    def spec(mode, seed, n=20):
        return parse_spec({"base": {"strategy": "cooperative", "profile": "0:-30", "t_end_s": 1.0},
                           "sweep": {"mode": mode, "samples": n, "seed": seed},
                           "vary": {"h0": {"fields": ["h0_heating_W_m2K", "h0_cooling_W_m2K"], "min": 60, "max": 70},
                                    "h2_heating_W_m2K3": {"min": 5e-4, "max": 1e-3, "log": True}}})
    for mode in ("random", "lhs"):
        a, b, c = spec(mode, 1).points(), spec(mode, 1).points(), spec(mode, 2).points()
        assert a == b and a != c
        h0 = np.array([p["h0"] for p in a])
        h2 = np.array([p["h2_heating_W_m2K3"] for p in a])
        assert np.all((60 <= h0) & (h0 <= 70)) and np.all((5e-4 <= h2) & (h2 <= 1e-3))
    lhs = np.array([p["h0"] for p in spec("lhs", 3).points()])
    # Latin hypercube: exactly one sample in each of the n equal strata
    assert sorted(np.floor((lhs - 60) / 10 * 20).astype(int).tolist()) == list(range(20))
    runs = spec("lhs", 3).runs()
    assert runs[0].spec.params.h0_heating_W_m2K == runs[0].spec.params.h0_cooling_W_m2K == runs[0].values["h0"]


@pytest.mark.parametrize("text, message", [
    ('[vary]\nh0_heating = [1.0]\n', "'h0_heating' is neither a parameter nor a run setting"),
    ('[vary]\nh0_heating_W_m2K = [60.0, "x"]\n', r"\[vary\] h0_heating_W_m2K.values\[1\]: 'x' is not a number"),
    ('[vary]\nh0_heating_W_m2K = [60.0, -5.0]\n', r"point 1 \(h0_heating_W_m2K = -5.0\): h0_heating_W_m2K = -5.0 is outside"),
    ('[vary]\nh0_heating_W_m2K = {min = 1, max = 2}\n', "min/max ranges need mode = 'random' or 'lhs'"),
    ('[vary]\nh0_heating_W_m2K = {start = 1, stop = 2}\n', "num is missing"),
    ('[vary]\nh0_heating_W_m2K = [60.0, 60.0]\n', "points 0 and 1 are the same run"),
    ('[vary]\nh0_heating_W_m2K = [60.0]\nh0 = {fields = ["h0_heating_W_m2K"], values = [1.0]}\n',
     "'h0_heating_W_m2K' is already set by"),
    ('[vary]\n', r"\[vary\]: is missing or empty"),
    ('[vary]\nh0_heating_W_m2K = {values = [1.0], step = 2}\n', "unknown key.*step"),
    ('[varry]\nx = 1\n[vary]\nh0_heating_W_m2K = [60.0]\n', "unknown table.*varry"),
    # a varied name that is one of the table's columns wrote it twice, and an unreadable table
    ('[vary]\nstatus = {fields = ["h0_heating_W_m2K"], values = [20.0, 30.0]}\n',
     r"\[vary\] status: is the name of one of the table's own columns"),
    ('[vary]\npoint = {fields = ["h0_heating_W_m2K"], values = [20.0]}\n', r"\[vary\] point: is the name"),
    ('[vary]\nseg0_start_s = {fields = ["h0_heating_W_m2K"], values = [20.0]}\n', r"\[vary\] seg0_start_s: is the"),
])
def test_bad_specs_name_field_and_value(tmp_path, text, message):
    p = _write(tmp_path, _spec(text))
    with pytest.raises(SweepSpecError, match=message):
        load_spec(p).runs()


@pytest.mark.parametrize("sweep, vary, message", [
    ('mode = "cube"', '[vary]\nx = [1]\n', r"\[sweep\] mode: 'cube' is not one of grid, list, random, lhs"),
    ('mode = "lhs"', '[vary]\nh0_heating_W_m2K = {min = 1, max = 2}\n', r"\[sweep\] samples: is required"),
    ('mode = "lhs"\nsamples = 4', '[vary]\nh0_heating_W_m2K = {min = 3, max = 2}\n', "min = 3.0 must be below max = 2.0"),
    ('mode = "lhs"\nsamples = 4', '[vary]\nstress_law = {min = 1, max = 2}\n', "not numeric"),
    ('mode = "random"\nsamples = 4', '[vary]\nh0_heating_W_m2K = [1.0, 2.0]\n', "samples within ranges"),
    ('samples = 4', '[vary]\nh0_heating_W_m2K = [1.0]\n', r"\[sweep\] samples: is only used with mode"),
    ('mode = "list"', '[vary]\nh0_heating_W_m2K = [1.0, 2.0]\nh2_heating_W_m2K3 = [1e-3]\n', "lengths differ"),
    ('chunk_size = 0', '[vary]\nh0_heating_W_m2K = [1.0]\n', r"\[sweep\] chunk_size: 0 must be >= 1"),
])
def test_bad_sweep_tables(tmp_path, sweep, vary, message):
    with pytest.raises(SweepSpecError, match=message):
        load_spec(_write(tmp_path, _spec(vary, sweep))).runs()


def test_bad_base_and_files(tmp_path):
    with pytest.raises(SweepSpecError, match=r"\[base\] t_end_s: 'long' is not a number"):
        load_spec(_write(tmp_path, _spec("[vary]\nh0_heating_W_m2K = [1.0]\n", base='t_end_s = "long"')))
    with pytest.raises(SweepSpecError, match=r"\[base\]: unknown key\(s\) tend"):
        load_spec(_write(tmp_path, _spec("[vary]\nh0_heating_W_m2K = [1.0]\n", base="tend = 1")))
    with pytest.raises(SweepSpecError, match="unknown parameter set 'nope'"):
        load_spec(_write(tmp_path, _spec("[vary]\nh0_heating_W_m2K = [1.0]\n", base='params = "nope"'))).runs()
    with pytest.raises(SweepSpecError, match=r"point 0 .*strategy open-loop needs a voltage program"):
        load_spec(_write(tmp_path, _spec("[vary]\nh0_heating_W_m2K = [1.0]\n", base='strategy = "open-loop"'))).runs()
    with pytest.raises(SweepSpecError, match="not valid TOML"):
        load_spec(_write(tmp_path, "[base\n"))
    with pytest.raises(SweepSpecError, match="sweep spec not found"):
        load_spec(tmp_path / "missing.toml")
    # a parameter file relative to the spec's folder, and varied run settings
    (tmp_path / "mine.toml").write_text('base = "paper2010"\nM_SF_Nm = 0.02\n')
    spec = load_spec(_write(tmp_path, _spec('[vary]\nprofile = ["0:-25", "0:-55"]\n',
                                            base='params = "mine.toml"\nt_end_s = 1.0')))
    runs = spec.runs()
    assert [r.spec.params.M_SF_Nm for r in runs] == [0.02, 0.02]
    assert [r.spec.profile.segments[0].target_deg for r in runs] == [-25.0, -55.0]


def test_scenario_base(tmp_path):
    scenarios = pytest.importorskip("smafinger.scenarios")
    name = next(n for n in scenarios.names() if n.startswith("fig8-h0-60-upper"))
    spec = load_spec(_write(tmp_path, _spec('[vary]\nh0 = {fields = ["h0_heating_W_m2K", "h0_cooling_W_m2K"], '
                                            'values = [61.0, 62.0]}\n', base=f'scenario = "{name}"\ndt_s = 0.002')))
    runs = spec.runs()
    ref = scenarios.get(name).spec()
    assert [r.spec.params.h0_cooling_W_m2K for r in runs] == [61.0, 62.0]
    assert runs[0].spec.dt_s == 0.002 and runs[0].spec.t_end_s == ref.t_end_s
    assert runs[0].spec.voltage == ref.voltage and runs[0].spec.strategy == ref.strategy
    with pytest.raises(SweepSpecError, match=r"\[base\] scenario.*no-such-scenario"):
        load_spec(_write(tmp_path, _spec("[vary]\nh0_heating_W_m2K = [1.0]\n", base='scenario = "no-such-scenario"')))


# ---- running -------------------------------------------------------------------------
def test_sweep_table_and_rerun_is_idempotent(tmp_path):
    spec = _write(tmp_path, SMALL)
    out = tmp_path / "res.parquet"
    rep = run_sweep(spec, out, workers=1)
    assert (rep.total, rep.ran, rep.resumed, rep.failed) == (6, 6, 0, 0)
    assert not sw.parts_dir(out).exists()
    df = pd.read_parquet(out)
    assert list(df.columns[:5]) == ["run_id", "point", "h0", "C_DF_heating_Nms", "status"]
    for c in ("electrical_energy_upper_J", "heat_upper_J", "peak_T_upper_C", "peak_stress_upper_Pa",
              "electrical_energy_lower_J", "heat_lower_J", "interlock_violations", "seg0_reached_s",
              "seg0_overshoot_deg", "theta_max_deg", "motion_start_s"):
        assert c in df.columns
    # energy named for what it is: with Eq. (11) read per metre (the paper's sets) the electrical
    # energy at the terminals is 1 / L_w^2 times the heat the model puts into the wire
    L_w = load_spec(spec).runs()[0].spec.params.wire_length_m
    assert np.allclose(df["electrical_energy_upper_J"], df["heat_upper_J"] / L_w**2, rtol=1e-9)
    assert (df["heat_upper_J"] > 0).all() and (df["heat_lower_J"] == 0).all()
    # the linear actuator's columns are there, and empty
    assert df[["heat_wire_J", "position_max_m", "seg0_target_m"]].isna().all().all()
    assert df["point"].tolist() == list(range(6)) and df["run_id"].is_unique
    assert (df["status"] == "ok").all() and (df["interlock_violations"] == 0).all()
    assert df.loc[0, "run_id"] == load_spec(spec).runs()[0].run_id
    # each row is the run made alone
    one = load_spec(spec).runs()[4]
    alone = sw.metrics_row(__import__("smafinger").engine.run.run_spec(one.spec))
    row = df.iloc[4]
    for k, v in alone.items():
        if k not in ("wall_s", "error"):
            assert row[k] == v or (np.isnan(v) and np.isnan(row[k])), k
    first = _frame(out)
    rep2 = run_sweep(spec, out, workers=1)
    assert (rep2.ran, rep2.resumed) == (0, 6)
    pd.testing.assert_frame_equal(_frame(out), first)


def test_a_base_set_no_run_could_use_does_not_stop_a_sweep_of_good_points(tmp_path):
    """Every point stable at the given step, the base set alone not (a 0.1 m wire pulling its
    20 g at rk4 1 ms: engine.numerics.unstable_step): the sweep ran every point, then failed
    writing the base's settings into the table's metadata, an internal error with no table
    (found by review). The base is no run: its settings are recorded, not checked."""
    spec = tmp_path / "stiff.toml"
    spec.write_text('[base]\nparams = "linear-bias-spring"\nset = { wire_length_m = 0.1, V_H_V = 1.2 }\n'
                    'strategy = "open-loop"\nvoltage = "0:0.6,1:0"\nt_end_s = 2.0\ndt_s = 0.001\n'
                    '[sweep]\nmode = "list"\n[vary]\nslider_mass_kg = [0.5, 0.1]\n')
    out = tmp_path / "stiff.parquet"
    rep = run_sweep(spec, out, workers=1)
    assert (rep.total, rep.ran, rep.failed) == (2, 2, 0)
    df = pd.read_parquet(out)
    assert (df["status"] == "ok").all() and (df["run_dt_s"] == 0.001).all()


def test_interrupted_sweep_resumes(tmp_path):
    spec = _write(tmp_path, SMALL.replace("[sweep]\n", "[sweep]\nchunk_size = 2\n"))
    out = tmp_path / "res.parquet"

    def stop(done, total):
        if done >= 2:
            raise KeyboardInterrupt

    with pytest.raises(SweepInterrupted, match="interrupted after 2 of 6 runs"):
        run_sweep(spec, out, workers=1, on_progress=stop)
    assert not out.exists()
    assert len(list(sw.parts_dir(out).glob("part-*.parquet"))) == 1
    rep = run_sweep(spec, out, workers=1)
    assert (rep.resumed, rep.ran) == (2, 4)
    ref = tmp_path / "ref.parquet"
    run_sweep(spec, ref, workers=1)
    pd.testing.assert_frame_equal(_frame(out), _frame(ref))


def test_killed_sweep_resumes_every_run_once(tmp_path):
    """SIGKILL a running `smafinger sweep` after some parts are written; rerun; every run once."""
    vary = '[vary]\nh0 = {fields = ["h0_heating_W_m2K", "h0_cooling_W_m2K"], start = 60.0, stop = 70.0, num = 40}\n' \
           'h2_heating_W_m2K3 = [5e-4, 1e-3]\n'
    spec = _write(tmp_path, _spec(vary, "chunk_size = 2\nsave_interval_s = 0", t_end=10.0))
    out = tmp_path / "res.parquet"
    parts = sw.parts_dir(out)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.Popen([sys.executable, "-m", "smafinger.cli", "sweep", str(spec), "--out", str(out),
                             "--workers", "2"], env=env, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and proc.poll() is None:
            if len(list(parts.glob("part-*.parquet"))) >= 3:
                break
            time.sleep(0.005)
        os.killpg(proc.pid, signal.SIGKILL)  # the sweep and its worker processes
    finally:
        proc.wait(timeout=30)
    n_parts = len(list(parts.glob("part-*.parquet")))
    assert not out.exists(), "the sweep finished before it could be killed"
    assert 3 <= n_parts < 40
    rep = run_sweep(spec, out, workers=2)
    assert rep.total == 80 and rep.resumed >= 6 and rep.resumed + rep.ran == 80
    df = pd.read_parquet(out)
    assert len(df) == 80 and df["run_id"].is_unique and df["point"].tolist() == list(range(80))
    assert set(df["run_id"]) == {r.run_id for r in load_spec(spec).runs()}
    assert not parts.exists()


def test_failed_runs_are_rows_and_count_as_done(tmp_path, monkeypatch):
    real = sw.metrics_row

    def flaky(result, traces_interval_s=None):
        if result.spec.params.C_DF_heating_Nms == 0.03:
            raise sw.SimulationError("numerical blow-up at t = 1 s (on purpose)")
        return real(result, traces_interval_s)

    monkeypatch.setattr(sw, "metrics_row", flaky)
    spec = _write(tmp_path, SMALL)
    out = tmp_path / "res.parquet"
    rep = run_sweep(spec, out, workers=1, traces=True)
    df = pd.read_parquet(out)
    assert rep.failed == 2 and (df["status"] == "error").sum() == 2
    bad = df[df["status"] == "error"]
    assert (bad["C_DF_heating_Nms"] == 0.03).all() and bad["electrical_energy_upper_J"].isna().all()
    assert bad["error"].str.contains("SimulationError: numerical blow-up").all()
    assert set(pd.read_parquet(rep.traces_out)["run_id"]) == set(df.loc[df["status"] == "ok", "run_id"])
    rep2 = run_sweep(spec, out, workers=1, traces=True)  # deterministic failures are not redone
    assert (rep2.ran, rep2.resumed) == (0, 6)


def test_traces_option(tmp_path):
    spec = _write(tmp_path, SMALL.replace("[sweep]\n", "[sweep]\ntraces_interval_s = 0.5\n"))
    out = tmp_path / "res.parquet"
    rep = run_sweep(spec, out, workers=1, traces=True)
    tr = pd.read_parquet(rep.traces_out)
    df = pd.read_parquet(out)
    assert rep.traces_out == tmp_path / "res.traces.parquet"
    assert set(tr["run_id"]) == set(df["run_id"])
    assert tr["point"].is_monotonic_increasing and set(tr["point"]) == set(df["point"])
    # compact: float32 signals, float64 time (the join key)
    assert tr["t_s"].dtype == np.float64 and tr["theta_deg"].dtype == np.float32
    one = tr[tr["run_id"] == df.loc[0, "run_id"]]
    assert one["t_s"].tolist() == [0.0, 0.5, 1.0, 1.5, 2.0]
    assert np.isclose(one["theta_deg"].max(), df.loc[0, "theta_max_deg"], atol=0.5)


def test_linear_actuator_sweep_has_its_own_columns(tmp_path):
    """A sweep of the linear bias-spring rig: per-wire columns by its wire's name, its coordinate in metres."""
    spec = parse_spec({"base": {"params": "linear-bias-spring", "strategy": "open-loop", "voltage": "0:12,2:0",
                                "t_end_s": 4.0},
                       "vary": {"bias_spring_K_N_m": [100.0, 400.0]}})
    out = tmp_path / "lin.parquet"
    rep = run_sweep(spec, out, workers=1, traces=True)
    df = pd.read_parquet(out)
    assert rep.failed == 0 and (df["status"] == "ok").all()
    p = spec.runs()[0].spec.params
    # 12 V at the terminals of the whole wire for 2 s: V^2 / (R_w L_w) t (the rig reads Eq. 11 whole-wire,
    # so the heat the model puts into the wire is the same energy)
    e = 12.0**2 / (p.resistance_ohm_per_m * p.wire_length_m) * 2.0
    assert np.allclose(df["electrical_energy_wire_J"], e, rtol=1e-6) and np.allclose(df["heat_wire_J"], e, rtol=1e-6)
    assert (df["position_max_m"] > 1e-4).all() and (df["motion_start_s"] > 0).all()
    # a stiffer bias spring: a shorter stroke
    assert df["position_max_m"].iloc[1] < df["position_max_m"].iloc[0]
    assert df["seg0_target_m"].notna().all() and df["seg0_target_deg"].isna().all()
    assert df[["electrical_energy_upper_J", "theta_max_deg"]].isna().all().all()
    tr = pd.read_parquet(rep.traces_out)
    assert tr["position_m"].notna().all() and tr["T_wire_C"].notna().all() and tr["theta_deg"].isna().all()


def test_fig8_local_physics():
    """Fig. 8's trend: lower h0 gives a larger range and an earlier start."""
    spec = parse_spec({"base": {"params": "paper2010-table2", "strategy": "open-loop",
                                "voltage": "0:8:0,8:0:0", "t_end_s": 20.0},
                       "vary": {"h0": {"fields": ["h0_heating_W_m2K", "h0_cooling_W_m2K"], "values": [60.0, 65.0, 70.0]}}})
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        run_sweep(spec, Path(d) / "f8.parquet", workers=1)
        df = pd.read_parquet(Path(d) / "f8.parquet")
    assert df["theta_max_deg"].is_monotonic_decreasing and df["theta_max_deg"].iloc[0] > df["theta_max_deg"].iloc[-1]
    assert df["motion_start_s"].is_monotonic_increasing


# ---- CLI -----------------------------------------------------------------------------
def _cli(args, cwd):
    from typer.testing import CliRunner
    import typer

    from smafinger.cli.sweep import sweep

    app = typer.Typer()
    app.command("sweep")(sweep)
    app.command("other")(lambda: None)  # keep 'sweep' as a sub-command
    old = os.getcwd()
    os.chdir(cwd)
    try:
        return CliRunner().invoke(app, ["sweep", *args])
    finally:
        os.chdir(old)


def test_cli(tmp_path):
    spec = _write(tmp_path, SMALL)
    r = _cli([str(spec), "--workers", "1"], tmp_path)
    assert r.exit_code == 0, r.output
    assert "wrote spec.parquet: 6 runs (0 already done, 0 failed)" in r.output
    assert (tmp_path / "spec.parquet").exists()
    for args, msg in [
        ([str(spec), "--out", "x.csv"], "--out x.csv: the results file must end in .parquet"),
        ([str(spec), "--workers", "0"], "--workers 0: must be >= 1"),
        ([str(tmp_path / "nope.toml")], "sweep spec not found"),
        ([str(spec), "--scheduler", "tcp://127.0.0.1:1", "--workers", "2"], "--workers applies to local runs only"),
        ([str(spec), "--out", str(tmp_path / "no" / "r.parquet")], "does not exist"),
    ]:
        r = _cli(args, tmp_path)
        assert r.exit_code == 2, (args, r.output)
        lines = [ln for ln in r.output.splitlines() if ln.startswith("smafinger: error:")]
        assert len(lines) == 1 and msg in lines[0], r.output
    bad = _write(tmp_path, _spec('[vary]\nh0_heating_W_m2K = [60.0, "x"]\n'), "bad.toml")
    r = _cli([str(bad)], tmp_path)
    assert r.exit_code == 2 and "h0_heating_W_m2K.values[1]: 'x' is not a number" in r.output
    assert not (tmp_path / "bad.parquet").exists() and not (tmp_path / "bad.parquet.parts").exists()
    # a file that is not a sweep table is never overwritten
    (tmp_path / "other.parquet").write_bytes(b"not parquet")
    r = _cli([str(spec), "--out", "other.parquet", "--workers", "1"], tmp_path)
    assert r.exit_code == 2 and "is not a smafinger sweep table" in r.output
    assert (tmp_path / "other.parquet").read_bytes() == b"not parquet"


# ---- issue 13: reliability ---------------------------------------------------------------
def _failing(predicate):
    real = sw.metrics_row

    def row(result, traces_interval_s=None):
        if predicate(result):
            raise sw.SimulationError("numerical blow-up (on purpose)")
        return real(result, traces_interval_s)

    return row


@pytest.mark.parametrize("fail, args, code, message", [
    (lambda r: True, [], 3, "every run failed"),
    (lambda r: r.spec.params.C_DF_heating_Nms == 0.03, [], 0, "2 of 6 runs failed"),
    (lambda r: r.spec.params.C_DF_heating_Nms == 0.03, ["--strict"], 3, "2 of 6 runs failed"),
    (lambda r: False, ["--strict"], 0, None),
])
def test_exit_status_says_whether_runs_failed(tmp_path, monkeypatch, fail, args, code, message):
    monkeypatch.setattr(sw, "metrics_row", _failing(fail))
    spec = _write(tmp_path, SMALL)
    r = _cli([str(spec), "--workers", "1", *args], tmp_path)
    assert r.exit_code == code, r.output
    assert (tmp_path / "spec.parquet").exists()  # the table is written either way
    if message:
        assert message in r.output
    else:
        assert "failed (rows" not in r.output
    # a rerun (everything resumed) says the same
    assert _cli([str(spec), "--workers", "1", *args], tmp_path).exit_code == code


def test_huge_grid_refused_with_its_size_before_anything_is_made(tmp_path):
    import tracemalloc

    vary = ('[vary]\nh0_heating_W_m2K = {start = 1.0, stop = 100.0, num = 10000}\n'
            'C_DF_heating_Nms = {start = 0.01, stop = 0.1, num = 10000}\n')
    p = _write(tmp_path, _spec(vary))
    tracemalloc.start()
    try:
        with pytest.raises(SweepSizeError, match=r"100,000,000 runs \(estimated: table .* GB, client memory .* GB\); "
                                                 r"that is above the limit of 1,000,000 runs: raise --max-runs"):
            run_sweep(p, tmp_path / "big.parquet", workers=1)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20e6  # the two 10,000-value axes, not 10^8 points
    assert list(tmp_path.iterdir()) == [p]
    # one name alone with 10^8 values is refused before its values are made
    with pytest.raises(SweepSpecError, match=r"h0.num: 100,000,000 values: .* above the limit of 1,000,000"):
        load_spec(_write(tmp_path, _spec('[vary]\nh0 = {fields = ["h0_heating_W_m2K"], start = 1.0, stop = 2.0, '
                                         'num = 100000000}\n'), "one.toml"))
    r = _cli([str(p)], tmp_path)
    assert r.exit_code == 2 and "100,000,000 runs" in r.output
    assert len([ln for ln in r.output.splitlines() if ln.startswith("smafinger: error:")]) == 1
    # --max-runs raises the limit
    assert sw.check_size(load_spec(p, max_runs=10**8), tmp_path / "big.parquet", False, 10**8).runs == 10**8


def test_bad_point_and_duplicates_refused_by_the_check_pass(tmp_path):
    bad = _write(tmp_path, _spec('[vary]\nh0_heating_W_m2K = [60.0, -5.0]\n'))  # spec.toml
    with pytest.raises(SweepSpecError, match=r"point 1 \(h0_heating_W_m2K = -5.0\): h0_heating_W_m2K = -5.0 is outside"):
        run_sweep(bad, tmp_path / "bad.parquet", workers=1)
    dup = _write(tmp_path, _spec('[vary]\nh0_heating_W_m2K = [60.0, 61.0, 60.0]\n'), "dup.toml")
    with pytest.raises(SweepSpecError, match="points 0 and 2 are the same run"):
        run_sweep(dup, tmp_path / "dup.parquet", workers=1)
    assert sorted(f.name for f in tmp_path.iterdir()) == ["dup.toml", "spec.toml"]  # nothing written


@pytest.mark.parametrize("workers", [1, 2])
def test_check_pass_ids_equal_run_ids_made_alone(tmp_path, workers):
    spec = load_spec(_write(tmp_path, SMALL))
    from smafinger.engine import batch

    with batch.make_pool(workers) as pool:
        checked = sw.check_points(spec, spec.template(), spec.point_source(), pool)
    assert [i.decode() for i in checked.ids.tolist()] == [r.run_id for r in spec.runs()]
    assert checked.n_segments == 1


@given(start=st.integers(0, 40), length=st.integers(0, 40), mode=st.sampled_from(["random", "lhs"]),
       seed=st.integers(0, 2**32 - 1))
@settings(max_examples=40, deadline=None)
def test_lazy_blocks_equal_the_whole_sample(start, length, mode, seed):
    spec = parse_spec({"base": {"strategy": "cooperative", "profile": "0:-30", "t_end_s": 1.0},
                       "sweep": {"mode": mode, "samples": 40, "seed": seed},
                       "vary": {"h0_heating_W_m2K": {"min": 60, "max": 70},
                                "M_SF_Nm": {"min": 1e-3, "max": 1e-1, "log": True}}})
    src = spec.point_source()
    whole = src.block(0, 40)
    part = src.block(start, start + length)
    assert part == {k: v[start:start + length] for k, v in whole.items()}


def test_grid_blocks_follow_the_product_order(tmp_path):
    import itertools

    spec = load_spec(_write(tmp_path, SMALL))
    h0 = spec.vary[0].values
    cdf = spec.vary[1].values
    assert spec.points() == [{"h0": a, "C_DF_heating_Nms": b} for a, b in itertools.product(h0, cdf)]
    assert spec.point_source().block(2, 5) == {"h0": [60.0, 70.0, 70.0], "C_DF_heating_Nms": [0.04, 0.02, 0.03]}


def _session_pids(sid: int) -> list[int]:
    pids = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text()
            except OSError:
                continue
            fields = stat[stat.rindex(")") + 2:].split()
            if fields[0] != "Z" and int(fields[3]) == sid:  # state, ppid, pgrp, session
                pids.append(int(d.name))
    return pids


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc to list a session's processes")
def test_sigkill_of_the_client_leaves_no_process(tmp_path):
    """Workers, forkserver and resource tracker all exit within seconds of the client's SIGKILL."""
    vary = '[vary]\nh0 = {fields = ["h0_heating_W_m2K", "h0_cooling_W_m2K"], start = 60.0, stop = 70.0, num = 200}\n'
    spec = _write(tmp_path, _spec(vary, "chunk_size = 1\nsave_interval_s = 0", t_end=20.0))
    out = tmp_path / "res.parquet"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.Popen([sys.executable, "-m", "smafinger.cli", "sweep", str(spec), "--out", str(out),
                             "--workers", "2"], env=env, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and proc.poll() is None:
            if list(sw.parts_dir(out).glob("part-*.parquet")):
                break
            time.sleep(0.01)
        running = _session_pids(proc.pid)
        assert proc.poll() is None and len(running) >= 4, running  # client, forkserver, tracker, workers
        os.kill(proc.pid, signal.SIGKILL)  # the client only
        proc.wait(timeout=10)
        deadline = time.monotonic() + 10
        while _session_pids(proc.pid) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert _session_pids(proc.pid) == []
    finally:
        for pid in _session_pids(proc.pid):  # never leave them behind, even if the test fails
            os.kill(pid, signal.SIGKILL)


def test_stale_temporaries_are_removed_and_only_ours(tmp_path, monkeypatch):
    from smafinger.analysis import sweep_store

    spec = _write(tmp_path, SMALL)
    out = tmp_path / "res.parquet"
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()  # a pid that has exited
    host = sweep_store._HOST
    stale = [tmp_path / f".res.parquet.{host}-{dead}.0123abcd.tmp", tmp_path / ".res.parquet.0123456789ab.tmp",
             tmp_path / f".res.traces.parquet.{host}-{dead}.0123abcd.tmp"]
    kept = [tmp_path / f".res.parquet.{host}-{os.getpid()}.0123abcd.tmp",  # a live writer
            tmp_path / f".res.parquet.otherhost-{dead}.0123abcd.tmp",     # another machine's
            tmp_path / ".res.parquet.abcdef012345.tmp",                    # recent, old-style
            tmp_path / ".other.parquet.0123456789ab.tmp", tmp_path / "res.parquet.tmp"]
    for f in stale + kept:
        f.write_bytes(b"x")
    old = time.time() - 2 * sweep_store.LEGACY_TMP_AGE_S
    os.utime(stale[1], (old, old))
    run_sweep(spec, out, workers=1)
    assert [f.exists() for f in stale] == [False] * 3
    assert [f.exists() for f in kept] == [True] * 5


def test_parts_and_outputs_are_fsynced(tmp_path, monkeypatch):
    synced = []
    real = os.fsync

    def fsync(fd):
        synced.append(os.readlink(f"/proc/self/fd/{fd}") if Path("/proc/self/fd").exists() else fd)
        return real(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    spec = _write(tmp_path, SMALL.replace("[sweep]\n", "[sweep]\nsave_interval_s = 0\nchunk_size = 3\n"))
    run_sweep(spec, tmp_path / "res.parquet", workers=1, traces=True)
    if Path("/proc/self/fd").exists():
        names = [Path(s).name for s in synced]
        assert sum(n.startswith(".part-") and n.endswith(".tmp") for n in names) == 4  # 2 parts x (rows, traces)
        assert sum(n.startswith(".res.parquet.") for n in names) == 1
        assert sum(n.startswith(".res.traces.parquet.") for n in names) == 1
        assert names.count("res.parquet.parts") >= 4 and names.count(tmp_path.name) >= 2  # the folders


def test_plain_progress_lines_when_not_a_terminal(tmp_path):
    import io

    from rich.console import Console

    buf = io.StringIO()
    console = Console(file=buf, force_terminal=False, width=200)
    spec = _write(tmp_path, SMALL.replace("[sweep]\n", "[sweep]\nchunk_size = 1\n"))
    run_sweep(spec, tmp_path / "res.parquet", workers=1, console=console, progress=False,
              progress_interval_s=1e-9)
    lines = [ln for ln in buf.getvalue().splitlines() if ln.startswith("sweep spec: ") and "runs (" in ln]
    assert len(lines) == 6 and lines[-1].startswith("sweep spec: 6/6 runs (100%), 0 failed,")
    assert all(ln.endswith(", 1 workers") for ln in lines)
    assert "\x1b[" not in buf.getvalue()  # no terminal codes in a log


def test_dashboard_link_is_printed():
    import io

    from rich.console import Console

    from smafinger.analysis.sweep_progress import Progress

    buf = io.StringIO()

    class Pool:
        dashboard_link = "http://127.0.0.1:8787/status"

    Progress(Console(file=buf), False, 10.0, "x").pool(Pool())
    assert buf.getvalue().strip() == "Dask dashboard: http://127.0.0.1:8787/status"


def test_the_writer_libraries_are_imported_while_the_first_rows_are_awaited(tmp_path, monkeypatch):
    """The run pass starts pyarrow's and pandas' import (sweep_store.preload_writer) once,
    before it waits for any row, so the first part written does not wait for it."""
    events = []
    real_part = sw.write_part
    monkeypatch.setattr(sw, "preload_writer", lambda: events.append("preload"))
    monkeypatch.setattr(sw, "write_part", lambda *a, **k: (events.append("part"), real_part(*a, **k))[1])
    spec = _write(tmp_path, SMALL.replace("[sweep]\n", "[sweep]\nsave_interval_s = 0\nchunk_size = 3\n"))
    run_sweep(spec, tmp_path / "res.parquet", workers=1)
    assert events == ["preload", "part", "part"]
    events.clear()
    run_sweep(spec, tmp_path / "res.parquet", workers=1)  # nothing left to run: nothing to write
    assert events == []


def test_preload_writer_imports_pandas_for_pyarrow_in_a_thread_the_process_waits_for():
    code = ("import sys\nfrom smafinger.analysis.sweep_store import preload_writer\n"
            "before = 'pandas' in sys.modules\nth = preload_writer()\nth.join()\n"
            "print(before, th.daemon, 'pandas' in sys.modules, 'pyarrow.parquet' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env=dict(os.environ, PYTHONPATH=str(SRC)))
    assert out.stdout.split() == ["False", "False", "True", "True"]


ABSURD = _spec('[vary]\nvoltage = ["0:8:0,1:0:0", "0:60:0,1:0:0"]\n', sweep='mode = "list"',
               base='params = "paper2010-table2"\nstrategy = "open-loop"\nt_end_s = 2.0\n')


def test_absurd_runs_are_flagged_in_their_warnings_column(tmp_path):
    """A run the plausibility check flags (60 V on the paper's wire: about 680 degC) says so in
    its row, with the run's own warnings; an ordinary run's column is empty; a rerun counts the
    same; the command says how many, and a flagged run is not a failed one (exit status 0)."""
    from smafinger.engine.run import run_spec

    spec = _write(tmp_path, ABSURD)
    out = tmp_path / "w.parquet"
    rep = run_sweep(spec, out, workers=1)
    df = pd.read_parquet(out)
    assert (rep.failed_total, rep.flagged_total) == (0, 1) and (df["status"] == "ok").all()
    assert df.loc[0, "warnings"] == ""
    hot = run_spec(load_spec(spec).runs()[1].spec).metrics["warnings"]
    assert hot and any("upper wire" in w and "austenite finish" in w for w in hot)
    assert df.loc[1, "warnings"] == sw.WARNINGS_SEPARATOR.join(hot) and df.loc[1, "peak_T_upper_C"] > 600.0
    assert run_sweep(spec, out, workers=1).flagged_total == 1  # resumed: read back from the table
    r = _cli([str(spec), "--out", "c.parquet", "--workers", "1"], tmp_path)
    assert r.exit_code == 0, r.output
    assert "1 of 2 runs have warnings" in r.output
    assert "runs have warnings" not in _cli([str(_write(tmp_path, SMALL)), "--workers", "1"], tmp_path).output


@pytest.mark.parametrize("first_fails", [True, False])
def test_a_part_that_opens_with_a_failed_run_keeps_the_other_runs_metrics(tmp_path, monkeypatch, first_fails):
    """A failed run's row has no metrics. When it was the first row of a part file, the part took
    its columns from that row alone (pyarrow's from_pylist), and every other run of the part
    came out of the table with status ok and NaN metrics."""
    spec = _write(tmp_path, SMALL.replace("[sweep]\n", "[sweep]\nchunk_size = 6\n"))
    ref = tmp_path / "ref.parquet"
    run_sweep(spec, ref, workers=1)
    failing = 0 if first_fails else 5
    monkeypatch.setattr(sw, "metrics_row", _failing(lambda r: r.spec == load_spec(spec).runs()[failing].spec))
    out = tmp_path / "res.parquet"
    assert run_sweep(spec, out, workers=1).failed == 1
    df, want = _frame(out), _frame(ref)
    ok = df["status"] == "ok"
    assert ok.sum() == 5 and df.loc[~ok, "point"].tolist() == [failing]
    metrics = [c for c in want.columns if c not in ("status", "error") and want[c].dtype.kind == "f"]
    assert metrics and df.loc[ok, "theta_max_deg"].notna().all()
    pd.testing.assert_frame_equal(df.loc[ok, metrics], want.loc[ok, metrics])


def test_a_part_keeps_the_segments_of_runs_with_more_segments_than_its_first(tmp_path):
    """The same for a varied profile: a 2-segment run after a 1-segment one in the same part
    lost its second segment's columns."""
    spec = _write(tmp_path, _spec('[vary]\nprofile = ["0:-25", "0:-25,3:-55"]\n', sweep='mode = "list"',
                                  base='params = "paper2010"\nstrategy = "cooperative"\nt_end_s = 6.0\n'))
    run_sweep(spec, tmp_path / "res.parquet", workers=1)
    df = _frame(tmp_path / "res.parquet")
    assert np.isnan(df.loc[0, "seg1_target_deg"]) and df.loc[1, "seg1_target_deg"] == -55.0
    assert df.loc[1, "seg1_start_s"] == pytest.approx(3.0)
    alone = sw.metrics_row(__import__("smafinger").engine.run.run_spec(load_spec(spec).runs()[1].spec))
    assert df.loc[1, "seg1_overshoot_deg"] == alone["seg1_overshoot_deg"]


def test_traces_survive_a_merge_stopped_between_its_two_files(tmp_path, monkeypatch):
    """The merge writes OUT.traces, then OUT. Stopped between the two after a spec that renumbers
    the runs, the next run read the new traces by the old table's point numbers, skipped the row
    groups holding some runs, and lost their samples for good (they counted as finished)."""
    from smafinger.analysis import sweep_merge

    monkeypatch.setattr(sweep_merge, "TRACE_BLOCK_SAMPLES", 21)  # a row group per run, as in a large sweep
    base = {"params": "paper2010-table2", "strategy": "open-loop", "voltage": "0:8:0,1:0:0", "t_end_s": 2.0}

    def spec(values):
        return parse_spec({"base": base, "vary": {"C_DF_heating_Nms": values}})

    out = tmp_path / "r.parquet"
    run_sweep(spec([0.02, 0.03, 0.04, 0.05]), out, workers=1, traces=True)
    renumbered = spec([0.01, 0.05, 0.04, 0.03, 0.02])
    real = sw.write_table

    def stopped(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(sw, "write_table", stopped)
    with pytest.raises(KeyboardInterrupt):
        run_sweep(renumbered, out, workers=1, traces=True)
    monkeypatch.setattr(sw, "write_table", real)
    rep = run_sweep(renumbered, out, workers=1, traces=True)
    assert rep.ran == 0  # the new point ran before the stop, and its part was kept
    tr = pd.read_parquet(sw.traces_path(out))
    per_point = tr.groupby("point").size().reindex(range(5), fill_value=0)
    assert (per_point == 21).all(), per_point.to_dict()
    df = pd.read_parquet(out)
    assert set(tr["run_id"]) == set(df["run_id"])


@pytest.mark.parametrize("output_s, traces_s", [(0.04, 0.1), (0.5, 0.1)])
def test_traces_interval_must_be_a_multiple_of_the_runs_output_interval(tmp_path, output_s, traces_s):
    """Traces keep every k-th output sample: at 0.04 s samples and a 0.1 s interval they were
    0.08 s apart in a file that said 0.1 s. Refused by the check pass, naming both, before
    anything is written (and so is an interval shorter than the samples')."""
    base = (f'params = "paper2010-table2"\nstrategy = "open-loop"\nvoltage = "0:8:0,1:0:0"\nt_end_s = 2.0\n'
            f'output_interval_s = {output_s}\n')
    spec = _write(tmp_path, _spec("[vary]\nC_DF_heating_Nms = [0.02, 0.03]\n", sweep=f"traces_interval_s = {traces_s}",
                                  base=base))
    with pytest.raises(SweepSpecError, match=rf"point 0 .*traces_interval_s = {traces_s:g} s is not a whole "
                                             rf"multiple of the run's output_interval_s = {output_s:g} s"):
        run_sweep(spec, tmp_path / "r.parquet", workers=1, traces=True)
    assert list(tmp_path.iterdir()) == [spec]
    rep = run_sweep(spec, tmp_path / "r.parquet", workers=1)  # without traces the interval does not matter
    assert rep.failed == 0


def test_traces_taken_at_another_interval_are_taken_again(tmp_path):
    """A rerun asking for another traces interval kept the runs' old traces (the interval is not
    part of a run's id) under a file that stated the new one (found by review: 21 samples a run
    at 0.1 s in a file saying 0.5 s). Traces files state their interval, and a run whose trace was
    taken at another counts as not finished."""
    base = 'params = "paper2010-table2"\nstrategy = "open-loop"\nvoltage = "0:8:0,1:0:0"\nt_end_s = 2.0\n'
    out = tmp_path / "r.parquet"
    first = _write(tmp_path, _spec("[vary]\nC_DF_heating_Nms = [0.02, 0.03]\n", sweep="traces_interval_s = 0.1",
                                   base=base), "a.toml")
    run_sweep(first, out, workers=1, traces=True)
    second = _write(tmp_path, _spec("[vary]\nC_DF_heating_Nms = [0.02, 0.03, 0.04]\n", sweep="traces_interval_s = 0.5",
                                    base=base), "b.toml")
    rep = run_sweep(second, out, workers=1, traces=True)
    assert (rep.ran, rep.resumed) == (3, 0)
    tr = pd.read_parquet(sw.traces_path(out))
    assert tr.groupby("point").size().to_dict() == {0: 5, 1: 5, 2: 5}
    assert np.allclose(np.diff(tr[tr["point"] == 0]["t_s"]), 0.5)
    assert traces_interval(sw.traces_path(out)) == 0.5
    assert run_sweep(second, out, workers=1, traces=True).ran == 0  # the same interval again: all finished


def test_a_broken_pool_says_the_finished_runs_are_saved_and_resumable(tmp_path, monkeypatch):
    """The pool's own message no longer claims what its caller keeps (reproduce keeps nothing);
    the sweep, which does keep its finished runs, says so and where."""
    from smafinger.engine import pools

    spec = parse_spec({"base": {"t_end_s": 0.5, "profile": "0:-30"}, "sweep": {"chunk_size": 1},
                       "vary": {"V_H_V": [6.0, 7.0, 8.0, 9.0]}})
    real = pools.SerialPool.map_tasks  # what workers=1 runs on

    def breaks_after_one(self, fn, items):
        for k, res in enumerate(real(self, fn, items)):
            if k == 1 and fn is not sw._check_item:  # the run pass, not the check pass
                raise pools.BatchError("a worker process died (killed)")
            yield res

    monkeypatch.setattr(pools.SerialPool, "map_tasks", breaks_after_one)
    with pytest.raises(pools.BatchError, match=r"a worker process died \(killed\); after 1 of 4 runs; finished runs "
                                               r"are saved in .* - run the same sweep again to resume"):
        run_sweep(spec, tmp_path / "t.parquet", workers=1)
    monkeypatch.setattr(pools.SerialPool, "map_tasks", real)
    rep = run_sweep(spec, tmp_path / "t.parquet", workers=1)
    assert rep.resumed == 1 and rep.ran == 3
