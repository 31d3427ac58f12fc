"""Scale benchmarks (a script, not a timed test): prints ratios measured in this one run.

1. Parallel vs serial: the Fig. 8 sweep's runs (``examples/sweep-fig8.toml``, 231 runs)
   in this process one after the other, and on a pool of worker processes (one per core),
   each run reduced to its table row in the worker. Goal: >= 1.8x on 2 cores.
2. Engine vs a straightforward SciPy ``solve_ivp`` implementation of the same model
   (``benchmarks/scipy_baseline.py``: plain-Python right-hand side) on the same case: the
   upper wire at 8 V for 6 s, then off, to 20 s (``voltage="0:8:0,6:0:0"``, parameter set
   ``paper2010`` with ``minor_loop_reversal_C = 0``, the branch rule the baseline
   implements). Goal: >= 200x. Accuracy: max |theta - theta_ref| on a 10 ms grid, with
   theta_ref from the baseline at rtol = 1e-10 (LSODA). A second case drives the same wire
   with a PWM program (80 % duty, 1 ms period, for 8 s) to show the cost of discontinuities.

Usage::

    PYTHONPATH=src python benchmarks/bench_scale.py [--repeat 3] [--quick]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from functools import partial
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "src"))
sys.path.insert(0, str(HERE))

from smafinger import simulate  # noqa: E402
from smafinger.analysis.sweep import load_spec, metrics_row  # noqa: E402
from smafinger.engine import batch  # noqa: E402
from smafinger.engine.run import make_spec, run_spec  # noqa: E402
from smafinger.parameters import get  # noqa: E402

import scipy_baseline  # noqa: E402

FIG8 = HERE.parent / "examples" / "sweep-fig8.toml"


def _time(fn, repeat):
    ts, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), min(ts), out


def _strip(rows):
    return [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]


def bench_parallel(repeat: int) -> dict:
    specs = [r.spec for r in load_spec(FIG8).runs()]
    n = batch.available_cores()
    reduce = partial(metrics_row)
    batch.warm_up()
    print(f"\n[1] parallel vs serial: {len(specs)} runs of the Fig. 8 sweep, {n} cores")
    t0 = time.perf_counter()
    pool = batch.LocalPool(n).start()
    start_s = time.perf_counter() - t0
    ser, par = [], []
    try:
        # alternate serial and parallel rounds, so that load from elsewhere hits both alike
        for _ in range(max(repeat, 5)):
            t0 = time.perf_counter()
            ser_rows = batch.run_batch(specs, workers=1, reduce=reduce)
            ser.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            par_rows = batch.run_batch(specs, pool=pool, reduce=reduce)
            par.append(time.perf_counter() - t0)
    finally:
        pool.close()
    ser_med, ser_min = statistics.median(ser), min(ser)
    par_med, par_min = statistics.median(par), min(par)
    cold_med, _, _ = _time(lambda: batch.run_batch(specs, workers=n, reduce=reduce), 1)
    same = _strip(ser_rows) == _strip(par_rows)
    print(f"    serial (this process)        : {ser_med:7.3f} s  ({1e3 * ser_med / len(specs):.1f} ms/run; min {ser_min:.3f})")
    print(f"    {n} worker processes (warm)    : {par_med:7.3f} s  (min {par_min:.3f}; pool start {start_s:.2f} s)")
    print(f"    {n} worker processes (cold)    : {cold_med:7.3f} s  (pool started and warmed inside)")
    print(f"    rows identical                : {same}")
    r = ser_med / par_med
    print(f"    RATIO parallel/serial (warm)  : {r:.2f}x median, {ser_min / par_min:.2f}x best of {len(ser)}  "
          f"(goal >= 1.8x on 2 cores; cold {ser_med / cold_med:.2f}x)")
    return {"ratio": r, "cold": ser_med / cold_med, "identical": same}


def _engine_case(params, voltage, repeat):
    spec = make_spec(params, "open-loop", voltage=voltage, t_end_s=20.0)
    run_spec(spec)
    med, mn, res = _time(lambda: simulate(params, "open-loop", voltage=voltage, t_end_s=20.0), repeat)
    kern = min(run_spec(spec).wall_s for _ in range(repeat))
    return med, kern, res.t[::10], res.theta_deg[::10]


def bench_scipy(repeat: int, quick: bool) -> dict:
    # the baseline switches kinetics branches on the sign of dT/dt: the same option on both sides
    p = get("paper2010").replace(minor_loop_reversal_C=0.0)
    out = {}
    cases = [("constant 8 V for 6 s", "0:8:0,6:0:0")]
    if not quick:
        pwm = ",".join(f"{k * 1e-3:.4f}:8:0,{k * 1e-3 + 8e-4:.4f}:0:0" for k in range(8000)) + ",8:0:0"
        cases.append(("PWM 80 % duty, 1 ms, for 8 s", pwm))
    for name, voltage in cases:
        print(f"\n[2] engine vs scipy solve_ivp, open loop, {name}, paper2010, 20 s")
        eng_s, kern_s, t, th_eng = _engine_case(p, voltage, repeat * 2)
        t_ref, th_ref, info_ref = scipy_baseline.simulate_baseline(p, voltage, method="LSODA", rtol=1e-10)
        assert np.allclose(t, t_ref)
        fine = simulate(p, "open-loop", voltage=voltage, t_end_s=20.0, dt_s=1e-4, output_interval_s=1e-3)
        err_eng = float(np.max(np.abs(th_eng - th_ref)))
        err_fine = float(np.max(np.abs(fine.theta_deg[::10] - th_ref)))
        print(f"    reference: baseline LSODA rtol 1e-10 ({info_ref['wall_s']:.2f} s, {info_ref['nfev']} RHS calls); "
              f"theta max {np.nanmax(th_ref):.3f} deg")
        print(f"    engine rk4 dt 1 ms            : {eng_s * 1e3:8.1f} ms per simulate() call "
              f"(kernel {kern_s * 1e3:.1f} ms); max |dtheta| {err_eng:.4f} deg  (dt 0.1 ms: {err_fine:.4f} deg)")
        rows = []
        for method, rtol in (("RK45", 1e-3), ("RK45", 1e-6), ("LSODA", 1e-6)):
            if voltage != "0:8:0,6:0:0" and rtol == 1e-3:
                continue
            _, th, info = scipy_baseline.simulate_baseline(p, voltage, method=method, rtol=rtol)
            err = float(np.nanmax(np.abs(th - th_ref)))
            ratio = info["wall_s"] / eng_s
            rows.append((method, rtol, info["wall_s"], err, ratio))
            print(f"    scipy {method:5s} rtol {rtol:<6g}       : {info['wall_s'] * 1e3:8.1f} ms "
                  f"({info['nfev']} RHS calls, {info['calls']} solve_ivp calls); max |dtheta| {err:.4f} deg; "
                  f"RATIO {ratio:.1f}x (vs kernel {info['wall_s'] / kern_s:.1f}x)")
        out[name] = {"engine_s": eng_s, "kernel_s": kern_s, "engine_err_deg": err_eng, "baselines": rows}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="repetitions per timing (median)")
    ap.add_argument("--quick", action="store_true", help="skip the PWM case (about 20 s of SciPy)")
    a = ap.parse_args()
    import os
    import platform

    print(f"smafinger scale benchmarks: python {platform.python_version()}, {os.cpu_count()} cpus, "
          f"load average {os.getloadavg()[0]:.2f} at start")
    par = bench_parallel(a.repeat)
    sci = bench_scipy(a.repeat, a.quick)
    print("\nsummary")
    print(f"    parallel vs serial            : {par['ratio']:.2f}x warm, {par['cold']:.2f}x with pool start (goal >= 1.8x)")
    for name, r in sci.items():
        best = {f"{m} rtol {rt:g}": (ratio, err) for m, rt, _, err, ratio in r["baselines"]}
        shown = "; ".join(f"{k}: {v[0]:.1f}x (its error {v[1]:.4f} deg)" for k, v in best.items())
        print(f"    engine vs scipy, {name}: {shown}; engine error {r['engine_err_deg']:.4f} deg (goal >= 200x)")
    print(f"    load average at end           : {os.getloadavg()[0]:.2f} (other processes on this machine skew timings)")


if __name__ == "__main__":
    main()
