"""The interpreted engine (engine.interpreted): the kernel run as plain Python (numba's JIT
disabled) gives the compiled kernel's results to rounding; ``auto`` answers a run without a
cached kernel interpreted and compiles the kernel in the background for the next."""

import dataclasses
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from smafinger.engine import interpreted
from smafinger.engine.compiled import kernels
from smafinger.engine.run import _prepared, make_spec, run_spec
from smafinger.paper import scenarios
from smafinger.parameters import get

CYCLE = ("paper2010", "cooperative", "0:-25,reach:-55,reach:-40")

#: one run per kernel variant and integrator: the paper's full cycle at the long step
#: (exponential), its Table II open-loop run at rk4 with the PWM resolved, the linear rig
#: (algebraic stress law, slider) in closed loop at rk4 and in open loop at its long step
#: (semi-implicit), the authors' solver on authors2020, a built-in controller (ControlChain), euler
CASES = {
    "full-cycle-long-step": lambda: make_spec(*CYCLE, t_end_s=45.0),
    "open-loop-rk4": lambda: make_spec("paper2010-table2", "open-loop", voltage="0:8:0,3:0:8", t_end_s=6.0),
    "linear-rig": lambda: make_spec("linear-bias-spring", "cooperative", "0:0.010,4:0.004", t_end_s=8.0),
    "authors-ode4": lambda: make_spec("authors2020", "independent", "0:-25:upper,5:-55:both", t_end_s=8.0,
                                      method="authors-ode4"),
    "fuzzy-pid": lambda: make_spec("paper2010", "cooperative", "0:-25,6:-55", t_end_s=10.0, controller="fuzzy-pid"),
    # the linear rig's long step: semi-implicit with the wire's stiffness implicit
    "linear-rig-long-step": lambda: make_spec("linear-bias-spring", "open-loop", voltage="0:0.6,3:0", drive="duty",
                                              t_end_s=6.0, method="semi-implicit", dt_s=5e-3, pwm="averaged"),
    "euler": lambda: make_spec("paper2010", "cooperative", "0:-25", t_end_s=3.0, method="euler", dt_s=2e-4),
    # a soft spring, sharply stiffened: the spring's Newton start overflows sinh (interpreted: an
    # OverflowError reported as a blow-up where the compiled run went on; found by review)
    "stiff-slack": lambda: make_spec(get("paper2010").replace(slack_penalty_per_mm=10.0, spring_K_N_m=10.0),
                                     "cooperative", "0:-25,reach:-55,reach:-40", t_end_s=4.0),
}


@pytest.mark.parametrize("case", CASES)
def test_the_interpreted_engine_gives_the_compiled_results_to_rounding(case):
    spec = CASES[case]()
    compiled = run_spec(spec, engine="compiled")
    plain = run_spec(spec, engine="interpreted")
    assert (compiled.engine, plain.engine) == ("compiled", "interpreted")
    assert plain.substeps == compiled.substeps
    assert plain.interlock_violations == compiled.interlock_violations
    np.testing.assert_array_equal(plain.segment_start_s, compiled.segment_start_s)
    np.testing.assert_array_equal(plain.segment_reached_s, compiled.segment_reached_s)
    a, b = plain.to_pandas(), compiled.to_pandas()
    assert list(a.columns) == list(b.columns)
    for col in a.columns:
        x, y = a[col].to_numpy(float), b[col].to_numpy(float)
        scale = max(float(np.max(np.abs(y))), 1e-300)
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-9 * scale, err_msg=col)


@pytest.mark.parametrize("case", ["overflow", "math-domain"])
def test_a_blow_up_interpreted_names_the_time_and_the_state(case):
    """The child's SimulationError reaches the caller, as the compiled kernel's does; Python's
    ``math`` raising (an overflow, cos(inf) in an RK4 stage) is the blow-up it stands for."""
    from smafinger.engine.run import SimulationError

    if case == "overflow":
        p = get("paper2010").replace(inertia_kg_m2=1e-9)  # as tests/test_engine.py's blow-up
        spec, coordinate = make_spec(p, "open-loop", voltage="0:8:0", t_end_s=5.0, dt_s=1e-3), "theta_rad"
    else:
        p = get("linear-bias-spring").replace(slider_mass_kg=1e-6)
        spec = make_spec(p, "open-loop", voltage="0:0.6", drive="duty", t_end_s=6.0, method="rk4", dt_s=1e-5)
        # rk4 at 5 ms, past make_spec's refusal of a step beyond the wire-slider mode's stability
        # (engine.numerics.unstable_step): a blow-up, not a run
        spec = dataclasses.replace(spec, dt_s=5e-3)
        coordinate = "position_m"
    for engine in ("compiled", "interpreted"):
        with pytest.raises(SimulationError, match=rf"blow-up at t = .* {coordinate}="):
            run_spec(spec, engine=engine)


def test_auto_interprets_only_a_short_run_without_a_cached_kernel():
    short = make_spec(*CYCLE, t_end_s=45.0)  # the long step: 1.3 s estimated
    reference = make_spec(*CYCLE, t_end_s=45.0, method="rk4")  # 25 s estimated
    long = make_spec(*CYCLE, t_end_s=300.0, method="rk4")
    assert interpreted.interpreted_estimate_s(short) < 2.0  # measured 1.2 s
    # the PWM's edges count: rk4 at 1 ms, exact, is 83,282 sub-steps, not 45,000 (measured 14.2 s)
    assert 14.2 < interpreted.interpreted_estimate_s(reference) < interpreted.INTERPRETED_LIMIT_S
    assert interpreted.choose("auto", False, short) == "interpreted"
    assert interpreted.choose("auto", False, reference) == "interpreted"
    assert interpreted.choose("auto", False, long) == "compiled"
    assert interpreted.choose("auto", True, short) == "compiled"
    for engine in ("compiled", "interpreted"):
        for cached in (False, True):
            assert interpreted.choose(engine, cached, long) == engine


def test_the_engine_setting_comes_from_the_argument_then_the_environment(monkeypatch):
    monkeypatch.setenv("SMAFINGER_ENGINE", "interpreted")
    assert interpreted.engine_setting(None) == "interpreted"
    assert interpreted.engine_setting("compiled") == "compiled"
    monkeypatch.delenv("SMAFINGER_ENGINE")
    assert interpreted.engine_setting(None) == "auto"
    monkeypatch.setenv("SMAFINGER_ENGINE", "jit")
    with pytest.raises(ValueError, match="SMAFINGER_ENGINE = 'jit' is not one of auto, compiled, interpreted"):
        interpreted.engine_setting(None)
    with pytest.raises(ValueError, match="engine = 'fast'"):
        interpreted.engine_setting("fast")


def test_a_bad_engine_in_the_environment_is_a_usage_error(tmp_path):
    env = dict(os.environ, SMAFINGER_ENGINE="jit")
    proc = subprocess.run([sys.executable, "-m", "smafinger.cli", "simulate", "--profile", "0:-25", "--t-end", "1",
                           "--summary", str(tmp_path / "never.json")], env=env, capture_output=True, text=True)
    assert proc.returncode == 2
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "SMAFINGER_ENGINE = 'jit'" in lines[0], proc.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_kernel_in_numbas_cache_counts_as_cached():
    """A fresh lookup table (as in a new process) finds the kernel on disk once it was compiled."""
    from smafinger.engine.compiled import CompiledKernels

    spec = scenarios.get("fig12-extension-v1").spec()
    run_spec(spec)
    call_args, key = _prepared(spec)[:2]
    assert kernels.cached(key, call_args) and CompiledKernels().cached(key, call_args)


def test_the_command_line_engine_option(tmp_path):
    from smafinger.cli import main

    out = tmp_path / "s.json"
    assert main(["simulate", "--profile", "0:-25", "--t-end", "2", "--no-progress", "--engine", "interpreted",
                 "--summary", str(out)]) == 0
    assert json.loads(out.read_text())["engine"] == "interpreted"
    with pytest.raises(ValueError, match="engine = 'jit'"):
        run_spec(make_spec(*CYCLE, t_end_s=1.0), engine="jit")


def test_the_interpreted_child_imports_the_callers_package(tmp_path):
    """The child gets this process's sys.path: it imports this very package (a copy first on the
    path, not an installed one), from any folder, with numba's JIT disabled."""
    import smafinger

    code = "import smafinger, numba; print(smafinger.__file__); print(numba.config.DISABLE_JIT)"
    out = subprocess.run([sys.executable, "-c", code], env=interpreted.child_env("run"), cwd=tmp_path,
                         capture_output=True, text=True, check=True).stdout.split()
    assert out == [smafinger.__file__, "1"]


def test_auto_compiles_when_the_child_fails(monkeypatch):
    spec = make_spec(*CYCLE, t_end_s=1.0)

    def broken(_spec):
        raise interpreted.InterpretedFailure("the child could not start")

    monkeypatch.setattr(interpreted, "run_interpreted", broken)
    monkeypatch.setattr(interpreted, "build_in_background", lambda _spec: None)
    monkeypatch.setattr(interpreted, "choose", lambda engine, cached, spec: "interpreted")
    assert run_spec(spec, engine="auto").engine == "compiled"
    with pytest.raises(interpreted.InterpretedFailure):
        run_spec(spec, engine="interpreted")


def _index_has_kernel(cache_dir: Path) -> bool:
    return any(cache_dir.rglob("kernel.run_kernel-*.nbi"))


def _wait_for_build(spec, cache_dir):
    """Until the background build of ``spec``'s kernel releases its lock (it holds it while compiling)."""
    import fcntl

    old = os.environ.get("NUMBA_CACHE_DIR")
    os.environ["NUMBA_CACHE_DIR"] = cache_dir
    try:
        path = interpreted._build_path(spec, ".lock")
    finally:
        if old is None:
            del os.environ["NUMBA_CACHE_DIR"]
        else:
            os.environ["NUMBA_CACHE_DIR"] = old
    with open(path, "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)


def test_a_fresh_install_answers_interpreted_then_compiles_in_the_background(fresh_install):
    """An empty numba cache (a fresh install): the first ``simulate`` is interpreted and says so;
    the kernel is compiled meanwhile by one background process; the next run loads it. The first
    run is started with the session (conftest.FreshInstall), so its compile overlaps other tests."""
    root, env = fresh_install.root, fresh_install.env
    spec = make_spec("linear-bias-spring", "cooperative", "0:0.010", t_end_s=3.0)
    rc, stderr = fresh_install.first_run(timeout_s=600)
    assert rc == 0, stderr
    assert "this run was interpreted" in stderr and "background" in stderr
    deadline = time.monotonic() + 600
    while not _index_has_kernel(root / "cache") and time.monotonic() < deadline:
        time.sleep(1.0)
    assert _index_has_kernel(root / "cache"), "the background compile left no kernel in the cache"
    _wait_for_build(spec, env["NUMBA_CACHE_DIR"])  # numba writes the index, then the kernel
    proc = subprocess.run(fresh_install.command(root / "run1.json"), env=env, capture_output=True, text=True,
                          cwd=root)
    assert proc.returncode == 0, proc.stderr
    assert "interpreted" not in proc.stderr
    summaries = [json.loads((root / f"run{i}.json").read_text()) for i in range(2)]
    assert [s["engine"] for s in summaries] == ["interpreted", "compiled"]
    assert summaries[0]["segments"][0]["reached_s"] == pytest.approx(summaries[1]["segments"][0]["reached_s"],
                                                                      abs=1e-9)


def test_a_run_s_metrics_with_numba_s_jit_off():
    """The plausibility check called a compiled function's ``py_func``, which does not exist with
    numba's JIT off: every run's metrics failed there (found by review)."""
    code = ("from smafinger import simulate; from smafinger.parameters import get\n"
            "r = simulate(get('linear-bias-spring').replace(wire_diameter_m=0.25e-3), 'open-loop', voltage='0:0.3,0.2:0',"
            " drive='duty', t_end_s=0.3)\n"
            "print(sum(w.startswith('resistance_ohm_per_m') for w in r.metrics['warnings']))")
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().splitlines()[-1] == "1"
