"""Scale benchmarks (a script, not a timed test): prints ratios measured in this one run.

1. Parallel vs serial: the Fig. 8 sweep's runs (``examples/sweep-fig8.toml``, 231 runs)
   in this process one after the other, and on a pool of worker processes (one per core),
   each run reduced to its table row in the worker. Goal: >= 1.8x on 2 cores. Beside it, the
   machine's ceiling: every worker runs the whole batch at once, as one task (the same work
   each, no hand-over), which is what the cores give that many busy processes. Also the first
   pool's start (its forkserver started then, engine/forking.py) and a batch on a new pool
   made afterwards (its workers fork from that forkserver, already warm).
2. Lean batches (issue 11), each in a fresh child process so that its peak memory
   (``ru_maxrss``) is the client's alone:
   a. 1,000 full-cycle runs (Fig. 15's co-operative -40 -> -25 -> -55 -> -40 deg cycle,
      60 s simulated, K_P varied) as a sweep on every core: wall time, client peak memory;
      at the scenario's numerics (rk4, 1 ms, exact PWM) and at the long step (exponential,
      5 ms, averaged PWM: 0.012 deg RMS, 0.11 deg max from rk4 at 0.1 ms on this scenario).
      Goal: <= 5 s and < 1 GB on 2 cores. Beside it, one worker's work per run at the long
      step, measured alone in this process, and the time that many runs take at that rate on
      these cores if they did not slow each other down (a bound no pool can beat).
   b. 100 runs of 20 s at 1 ms returning results: full ``SimulationResult`` objects
      (``run_batch``) against :class:`~smafinger.engine.batch.Compact` (all signals, float32)
      and against streaming them with ``iter_batch`` (each written away as it comes).
3. The client's own cost per run in a sweep (chunks made and sent, rows received and
   saved), measured with the simulations replaced by their recorded rows: how many
   workers one client keeps busy (goal: >= 0.8 x the cores of the cluster).
4. Engine vs a straightforward SciPy ``solve_ivp`` implementation of the same model
   (the test oracle, ``tests/oracle``: plain-Python right-hand side) on the same case: the
   upper wire at 8 V for 6 s, then off, to 20 s (``voltage="0:8:0,6:0:0"``, parameter set
   ``paper2010``: return-point memory on both sides, the oracle's reversals and wiped-out
   loops as events).
   Goal: >= 200x. Accuracy: max |theta - theta_ref| on a 10 ms grid, with
   theta_ref from the baseline at rtol = 1e-10 (LSODA). A second case drives the same wire
   with a PWM program (80 % duty, 1 ms period, for 8 s) to show the cost of discontinuities.

Usage::

    PYTHONPATH=src python benchmarks/bench_scale.py [--repeat 3] [--quick]

``--quick`` skips the PWM SciPy case and runs 200 instead of 1,000 full cycles; ``--only
parallel lean`` runs those sections alone.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import pickle
import statistics
import subprocess
import sys
import tempfile
import time
from functools import partial
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "src"))
sys.path.insert(0, str(HERE.parent / "tests"))

from smafinger import simulate  # noqa: E402
from smafinger.analysis.sweep import load_spec, metrics_row  # noqa: E402
from smafinger.engine import batch  # noqa: E402
from smafinger.engine.run import make_spec, run_spec  # noqa: E402
from smafinger.parameters import get  # noqa: E402

from oracle import simulate_baseline  # noqa: E402

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


def _same_rows(a, b) -> bool:
    """The rows equal but for their wall times, a NaN equal to a NaN (NaN != NaN made every table
    with an empty column, e.g. the other mechanism's, print False)."""
    def cell(x, y):
        return x == y or (isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y))
    a, b = _strip(a), _strip(b)
    return len(a) == len(b) and all(r.keys() == s.keys() and all(cell(r[k], s[k]) for k in r) for r, s in zip(a, b))


def bench_parallel(repeat: int) -> dict:
    specs = [r.spec for r in load_spec(FIG8).runs()]
    n = batch.available_cores()
    reduce = partial(metrics_row)
    batch.warm_up()
    print(f"\n[1] parallel vs serial: {len(specs)} runs of the Fig. 8 sweep, {n} cores")
    t0 = time.perf_counter()
    pool = batch.LocalPool(n).start()
    start_s = time.perf_counter() - t0
    # the machine's ceiling: every worker runs the whole batch as one task, all at once (the same
    # work each, no hand-over): what n busy processes get from these cores
    ser, par, ceil = [], [], []
    try:
        # alternate serial and parallel rounds, so that load from elsewhere hits both alike
        for _ in range(max(repeat, 5)):
            t0 = time.perf_counter()
            ser_rows = batch.run_batch(specs, workers=1, reduce=reduce)
            ser.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            par_rows = batch.run_batch(specs, pool=pool, reduce=reduce)
            par.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            batch.run_batch(specs * n, pool=pool, reduce=reduce, chunk_size=len(specs))
            ceil.append((time.perf_counter() - t0) / n)  # per batch
    finally:
        pool.close()
    ser_med, ser_min = statistics.median(ser), min(ser)
    par_med, par_min = statistics.median(par), min(par)
    ceil_med = statistics.median(ceil)
    cold_med, _, _ = _time(lambda: batch.run_batch(specs, workers=n, reduce=reduce), 1)
    same = _same_rows(ser_rows, par_rows)
    print(f"    serial (this process)        : {ser_med:7.3f} s  ({1e3 * ser_med / len(specs):.1f} ms/run; min {ser_min:.3f})")
    print(f"    {n} worker processes (warm)    : {par_med:7.3f} s  (min {par_min:.3f}; pool start {start_s:.2f} s)")
    print(f"    {n} worker processes (new pool): {cold_med:7.3f} s  (a new pool, started inside: its workers "
          "fork from the forkserver the first pool started)")
    print(f"    {n} whole batches at once       : {ceil_med:7.3f} s  a batch (one task per worker, no hand-over: "
          "the ceiling of these cores)")
    print(f"    rows identical                : {same}")
    r = ser_med / par_med
    print(f"    RATIO parallel/serial (warm)  : {r:.2f}x median, {ser_min / par_min:.2f}x best of {len(ser)}  "
          f"(goal >= 1.8x on 2 cores; new pool {ser_med / cold_med:.2f}x)")
    reach = statistics.median(c / p for c, p in zip(ceil, par))  # round by round: the same load on both
    print(f"    RATIO ceiling/serial          : {ser_med / ceil_med:.2f}x median; the pool reaches "
          f"{reach:.0%} of it (median of the rounds)")
    return {"ratio": r, "cold": ser_med / cold_med, "identical": same, "ceiling": ser_med / ceil_med}


def _engine_case(params, voltage, repeat):
    # rk4 at 1 ms, as printed (the long step would be this constant-voltage case's default)
    spec = make_spec(params, "open-loop", voltage=voltage, t_end_s=20.0, method="rk4")
    run_spec(spec)
    med, mn, res = _time(lambda: simulate(params, "open-loop", voltage=voltage, t_end_s=20.0, method="rk4"), repeat)
    kern = min(run_spec(spec).wall_s for _ in range(repeat))
    return med, kern, res.t[::10], res.theta_deg[::10]


def bench_scipy(repeat: int, quick: bool) -> dict:
    # the oracle follows the set's hysteresis option (return-point memory): the same rule on both sides
    p = get("paper2010")
    out = {}
    cases = [("constant 8 V for 6 s", "0:8:0,6:0:0")]
    if not quick:
        pwm = ",".join(f"{k * 1e-3:.4f}:8:0,{k * 1e-3 + 8e-4:.4f}:0:0" for k in range(8000)) + ",8:0:0"
        cases.append(("PWM 80 % duty, 1 ms, for 8 s", pwm))
    for name, voltage in cases:
        print(f"\n[4] engine vs scipy solve_ivp, open loop, {name}, paper2010, 20 s")
        eng_s, kern_s, t, th_eng = _engine_case(p, voltage, repeat * 2)
        t_ref, th_ref, info_ref = simulate_baseline(p, voltage, method="LSODA", rtol=1e-10)
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
            _, th, info = simulate_baseline(p, voltage, method=method, rtol=rtol)
            err = float(np.nanmax(np.abs(th - th_ref)))
            ratio = info["wall_s"] / eng_s
            rows.append((method, rtol, info["wall_s"], err, ratio))
            print(f"    scipy {method:5s} rtol {rtol:<6g}       : {info['wall_s'] * 1e3:8.1f} ms "
                  f"({info['nfev']} RHS calls, {info['calls']} solve_ivp calls); max |dtheta| {err:.4f} deg; "
                  f"RATIO {ratio:.1f}x (vs kernel {info['wall_s'] / kern_s:.1f}x)")
        out[name] = {"engine_s": eng_s, "kernel_s": kern_s, "engine_err_deg": err_eng, "baselines": rows}
    return out



# ---------------------------------------------------------------------------------------
# [2] lean batches, each in a child process (its ru_maxrss is the client's peak alone)
# ---------------------------------------------------------------------------------------
_CHILD = r"""
import json, resource, sys, time
from pathlib import Path
sys.path.insert(0, {src!r})
def main():
    case, n, tmp = sys.argv[1], int(sys.argv[2]), Path(sys.argv[3])
    from smafinger.engine import batch
    from smafinger.engine.run import make_spec
    t0 = time.perf_counter()
    extra = {{}}
    if case.startswith("sweep"):
        from smafinger.analysis.sweep import parse_spec, run_sweep
        base = {{"scenario": "fig15-cooperative-v1"}}
        if case == "sweep-long":  # the long-step numerics (engine.numerics.LONG_STEP)
            base.update(method="exponential", dt_s=0.005, pwm="averaged")
        spec = parse_spec({{"base": base,
                           "vary": {{"K_P_per_rad": {{"start": 2000.0, "stop": 4000.0, "num": n}}}}}})
        rep = run_sweep(spec, tmp / "cycle.parquet")
        extra = {{"failed": rep.failed_total, "client_ms_per_run": 1e3 * rep.client_s_per_run}}
    else:
        from smafinger.parameters import get
        t2 = get("paper2010-table2")
        specs = [make_spec(t2.replace(h0_heating_W_m2K=60.0 + i * 0.01), "open-loop", voltage="0:8:0,8:0:0",
                           t_end_s=20.0) for i in range(n)]
        if case == "full":
            out = batch.run_batch(specs)
            extra = {{"held_MB": sum(r.to_pandas().memory_usage().sum() for r in out[:1]) * n / 1e6}}
        elif case == "compact":
            out = batch.run_batch(specs, reduce=batch.Compact())
            extra = {{"held_MB": sum(r.nbytes for r in out) / 1e6}}
        else:  # stream: each compact result written away as it comes
            import pyarrow as pa, pyarrow.parquet as pq
            w = None
            for i, ok, r in batch.iter_batch(specs, reduce=batch.Compact()):
                t = pa.table(r.signals)
                w = w or pq.ParquetWriter(str(tmp / "stream.parquet"), t.schema)
                w.write_table(t)
            w.close()
            extra = {{"written_MB": (tmp / "stream.parquet").stat().st_size / 1e6}}
    wall = time.perf_counter() - t0
    print(json.dumps({{"wall_s": wall, "peak_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                      **extra}}))
if __name__ == "__main__":
    main()
"""


def _child(case: str, n: int) -> dict:
    with tempfile.TemporaryDirectory() as d:
        script = Path(d) / "child.py"
        script.write_text(_CHILD.format(src=str(HERE.parent / "src")))
        r = subprocess.run([sys.executable, str(script), case, str(n), d], capture_output=True, text=True)
    if r.returncode:
        raise RuntimeError(f"child {case} failed:\n{r.stderr[-2000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def _serial_per_run_s(n: int = 40) -> float:
    """Seconds a run of the long-step full-cycle sweep takes in one process (point built, run,
    row made and saved): a worker's work per run with no other process on the cores. Timed
    from the first chunk's end to the last's, so the sweep's fixed costs (check pass, table
    written) are left out."""
    from smafinger.analysis.sweep import parse_spec, run_sweep

    spec = parse_spec({"base": {"scenario": "fig15-cooperative-v1", "method": "exponential", "dt_s": 0.005,
                                "pwm": "averaged"},
                       "vary": {"K_P_per_rad": {"start": 2000.0, "stop": 4000.0, "num": n}}})
    batch.warm_up()
    marks: list[tuple[int, float]] = []
    with tempfile.TemporaryDirectory() as d:
        run_sweep(spec, Path(d) / "serial.parquet", workers=1, chunk_size=n // 4,
                  on_progress=lambda done, total: marks.append((done, time.perf_counter())))
    (d0, t0), (d1, t1) = marks[0], marks[-1]
    return (t1 - t0) / (d1 - d0)


def bench_lean(quick: bool) -> dict:
    n_cycle = 200 if quick else 1000
    print(f"\n[2a] {n_cycle} full-cycle runs (Fig. 15 co-operative, 60 s simulated) as a sweep on "
          f"{batch.available_cores()} cores")
    out = {}
    for case, label in (("sweep", "the scenario's numerics (rk4, 1 ms, exact PWM)"),
                        ("sweep-long", "the long step (exponential, 5 ms, averaged PWM)")):
        cyc = out[case] = _child(case, n_cycle)
        per_run = cyc["wall_s"] / n_cycle
        print(f"    {label}: wall {cyc['wall_s']:.1f} s ({1e3 * per_run:.1f} ms per run, pool start and check pass "
              f"included); client peak {cyc['peak_MB']:.0f} MB; failed {cyc['failed']}; client "
              f"{cyc['client_ms_per_run']:.3f} ms/run in the loop  (goal: 1,000 in <= 5 s, < 1 GB)")
    one = _serial_per_run_s()
    cores = batch.available_cores()
    print(f"    the long step, one worker's work alone (a sweep of 40 runs in this process): {1e3 * one:.1f} ms a run; "
          f"{n_cycle} runs on {cores} cores at that rate take >= {n_cycle * one / cores:.1f} s even with no "
          f"contention between the cores")
    out["serial_s_per_run"] = one
    print("\n[2b] 100 runs of 20 s at 1 ms, results returned (peak memory of the client)")
    out["cycle"] = out["sweep"]
    for case, label in (("full", "run_batch, full SimulationResults"), ("compact", "run_batch, Compact() float32"),
                        ("stream", "iter_batch + Compact(), streamed to parquet")):
        r = _child(case, 100)
        out[case] = r
        held = f"; results held {r['held_MB']:.0f} MB" if "held_MB" in r else f"; {r['written_MB']:.0f} MB written"
        print(f"    {label:45s}: peak {r['peak_MB']:6.0f} MB, {r['wall_s']:.1f} s{held}")
    print(f"    RATIO peak full / compact: {out['full']['peak_MB'] / out['compact']['peak_MB']:.2f}x, "
          f"full / streamed: {out['full']['peak_MB'] / out['stream']['peak_MB']:.2f}x")
    return out


# ---------------------------------------------------------------------------------------
# [3] the client's cost per run, simulations replaced by recorded rows
# ---------------------------------------------------------------------------------------
def bench_client(repeat: int, n: int = 20000) -> dict:
    from smafinger.analysis import sweep as sw
    from smafinger.analysis.sweep_rows import run_block

    spec = sw.parse_spec({"base": {"params": "paper2010-table2", "strategy": "open-loop",
                                   "voltage": "0:8:0,8:0:0", "t_end_s": 20.0},
                          "vary": {"h0_heating_W_m2K": {"start": 60.0, "stop": 70.0, "num": n}}})
    template, points = spec.template(), spec.point_source()
    first = {"h0_heating_W_m2K": [60.0]}
    real = run_block(template, [0], [sw.run_id(template.build({"h0_heating_W_m2K": 60.0}))], first)
    row = real.rows[0]
    ids = np.array([f"{i:016x}".encode() for i in range(n)], dtype="S16")
    todo = np.ones(n, dtype=bool)
    size = batch.auto_chunk_size(n, 64)  # as for a 64-worker cluster
    ts = []
    for _ in range(repeat):
        with tempfile.TemporaryDirectory() as d:
            saver = sw._Saver(Path(d) / "x.parquet.parts", 1.0, False)
            t0 = time.perf_counter()
            for item in sw._run_items(template, points, ids, todo, size):
                pickle.loads(pickle.dumps(item))                      # the task goes out
                rows = [dict(row, run_id=i, point=p) for p, i in zip(item[1], item[2])]
                block = pickle.loads(pickle.dumps(type(real)(rows, None, 0)))  # its rows come back
                saver.add(block)
            saver.flush()
            ts.append((time.perf_counter() - t0) / n)
    c = statistics.median(ts)
    print(f"\n[3] the client's own work per run ({n} runs, chunks of {size}, rows saved as parts every 1 s)")
    print(f"    {1e6 * c:.1f} us per run (median of {repeat}; min {1e6 * min(ts):.1f})")
    res = {"client_s": c}
    for label, run_s in (("Fig. 8 run, 20 s open loop", 0.007), ("full cycle, 60 s co-operative", 0.060)):
        busy = run_s / c
        print(f"    {label} ({1e3 * run_s:.0f} ms of work): one client keeps {busy:,.0f} workers busy "
              f"(a 64-core cluster at {min(1.0, busy / 64):.2f} x its cores; goal >= 0.8)")
        res[label] = busy
    return res


#: the sections, in the order they run: [1] parallel, [2] lean, [3] client, [4] scipy
SECTIONS = ("parallel", "lean", "client", "scipy")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="repetitions per timing (median)")
    ap.add_argument("--quick", action="store_true", help="skip the PWM case (about 20 s of SciPy)")
    ap.add_argument("--only", nargs="+", choices=SECTIONS, default=list(SECTIONS),
                    help="run these sections only (default: all)")
    a = ap.parse_args()
    import os
    import platform

    print(f"smafinger scale benchmarks: python {platform.python_version()}, {os.cpu_count()} cpus, "
          f"load average {os.getloadavg()[0]:.2f} at start")
    par = bench_parallel(a.repeat) if "parallel" in a.only else None
    lean = bench_lean(a.quick) if "lean" in a.only else None
    cli = bench_client(a.repeat) if "client" in a.only else None
    sci = bench_scipy(a.repeat, a.quick) if "scipy" in a.only else {}
    print("\nsummary")
    if par:
        print(f"    parallel vs serial            : {par['ratio']:.2f}x warm, {par['cold']:.2f}x on a new pool "
              f"(goal >= 1.8x; this machine's ceiling {par['ceiling']:.2f}x)")
    for case, label in (("sweep", "reference"), ("sweep-long", "long step")) if lean else ():
        cyc = lean[case]
        print(f"    full cycles as a sweep ({label:9s}): {cyc['wall_s']:.1f} s, client peak {cyc['peak_MB']:.0f} MB "
              f"(goal 1,000 in <= 5 s, < 1 GB)")
    if lean:
        print(f"    100 x 20 s results, peak      : full {lean['full']['peak_MB']:.0f} MB, compact "
              f"{lean['compact']['peak_MB']:.0f} MB, streamed {lean['stream']['peak_MB']:.0f} MB")
    if cli:
        print(f"    client per run                : {1e6 * cli['client_s']:.1f} us: keeps "
              f"{cli['Fig. 8 run, 20 s open loop']:,.0f} workers busy at 7 ms per run (goal >= 0.8 x cores)")
    for name, r in sci.items():
        best = {f"{m} rtol {rt:g}": (ratio, err) for m, rt, _, err, ratio in r["baselines"]}
        shown = "; ".join(f"{k}: {v[0]:.1f}x (its error {v[1]:.4f} deg)" for k, v in best.items())
        print(f"    engine vs scipy, {name}: {shown}; engine error {r['engine_err_deg']:.4f} deg (goal >= 200x)")
    print(f"    load average at end           : {os.getloadavg()[0]:.2f} (other processes on this machine skew timings)")


if __name__ == "__main__":
    main()
