"""What bounds issue 11's unmet goals on this machine: each goal beside the floors measured under it.

A script printing ratios, not a timed test. Each section measures its cases side by side
(interleaved rounds, medians; ratios as the median of the rounds' own ratios):

1. The full cycle's loop (goal: <= 2 ms at the default settings, every signal recorded at
   1 ms). The default; the same run recording only its metrics' signals; the step loop with no
   samples between its ends (``output_interval_s`` = ``t_end_s``); the same at 10 ms steps.
   Beside them, writing the default's samples alone (35 float64 signals x 45,001 samples,
   12.6 MB): as the kernel writes them (a compiled loop, sample by sample into one row per
   signal) and as one contiguous fill (the memory's own speed).
2. A cached ``simulate`` process (goal: <= 1 s): Python alone, ``import numpy``, ``import
   numba``, ``import scipy.linalg`` (numba's registries import it to check for BLAS the
   first time any compiled function runs, cached or not) and numba's floor (a cached one-line
   function called once, whole process); beside them the other libraries a command or a
   sweep's client imports: typer's command machinery and pandas.
3. 1,000 full-cycle sweep runs in <= 5 s on 2 cores: one worker's work per run, alone in its
   process (``bench_scale``'s measure, over 120 runs); a 2-run ``smafinger sweep`` process (the
   sweep's fixed cost: start, pool, check pass, table). The bound: fixed cost + runs x work per
   run / cores, as if the cores did not slow each other down (``bench_scale.py``'s section 1
   measures what they give together: its ceiling, against the 1.8x goal).

Usage::

    PYTHONPATH=src python benchmarks/bench_floors.py [--rounds 7] [--only loop process sweep]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SRC = HERE.parent / "src"
sys.path.insert(0, str(SRC))
sys.path.insert(0, str(HERE))

from bench_speed import _FLOOR_MODULE, _process_s  # noqa: E402

SECTIONS = ("loop", "process", "sweep")


def _rounds(cases: dict, rounds: int) -> dict[str, list[float]]:
    """Every case (a callable returning seconds) once per round, in turn."""
    times: dict[str, list[float]] = {k: [] for k in cases}
    for _ in range(rounds):
        for k, f in cases.items():
            times[k].append(f())
    return times


def _ratio(times: dict, a: str, b: str) -> float:
    return statistics.median(x / y for x, y in zip(times[a], times[b]))


# ---------------------------------------------------------------------------------------
# [1] the full cycle's loop
# ---------------------------------------------------------------------------------------
def _writer():
    from smafinger.jit import njit

    @njit
    def write(mech, wires, n):  # one sample at a time, every signal's row, as signals.record_sample
        for j in range(n):
            x = j * 1e-3
            for k in range(mech.shape[0]):
                mech[k, j] = x + k
            for w in range(wires.shape[0]):
                for k in range(wires.shape[1]):
                    wires[w, k, j] = x + k + w

    return write


def bench_loop(rounds: int, repeat: int = 9) -> None:
    from smafinger.engine.run import make_spec, run_spec
    from smafinger.engine.signals import new_outputs

    base = make_spec("paper2010", "cooperative", "0:-25,reach:-55,reach:-40", t_end_s=45.0)
    long10 = dataclasses.replace(base, dt_s=0.01)
    runs = {
        "default": (base, "all"),
        "metrics signals": (base, "metrics"),
        "no samples": (dataclasses.replace(base, output_interval_s=base.t_end_s), "metrics"),
        "10 ms, no samples": (dataclasses.replace(long10, output_interval_s=base.t_end_s), "metrics"),
    }
    n = int(round(base.t_end_s / base.output_interval_s)) + 1
    mech, wires = new_outputs(n, len(base.params.wire_names))
    write = _writer()
    write(mech, wires, n)
    flat = np.empty(mech.size + wires.size)

    def best_of(f) -> float:
        out = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            f()
            out.append(time.perf_counter() - t0)
        return min(out)

    cases = {k: (lambda s=s, r=r: min(run_spec(s, record=r).wall_s for _ in range(repeat)))
             for k, (s, r) in runs.items()}
    cases["write, as the kernel"] = lambda: best_of(lambda: write(mech, wires, n))
    cases["write, contiguous"] = lambda: best_of(lambda: flat.fill(1.0))
    for s, r in runs.values():
        run_spec(s, record=r)  # compiled or loaded, outside the timing
    times = _rounds(cases, rounds)
    med = {k: 1e3 * statistics.median(v) for k, v in times.items()}
    print(f"\n[1] the co-operative full cycle's loop ({base.t_end_s:g} s; its default: {base.method}, "
          f"{1e3 * base.dt_s:g} ms, {base.pwm} PWM); best of {repeat} per round, medians of {rounds} rounds")
    print(f"    default, every signal every 1 ms  : {med['default']:6.2f} ms   (goal <= 2 ms)")
    print(f"    only the metrics' signals, 1 ms   : {med['metrics signals']:6.2f} ms")
    print(f"    the step loop, no samples         : {med['no samples']:6.2f} ms   RATIO default/this "
          f"{_ratio(times, 'default', 'no samples'):.2f}x")
    print(f"    ... at 10 ms steps                : {med['10 ms, no samples']:6.2f} ms   RATIO default/this "
          f"{_ratio(times, 'default', '10 ms, no samples'):.2f}x")
    print(f"    writing the default's samples ({mech.size + wires.size:,} float64, "
          f"{8 * (mech.size + wires.size) / 1e6:.1f} MB) alone:")
    print(f"      sample by sample into a row per signal, as the kernel: {med['write, as the kernel']:6.2f} ms")
    print(f"      one contiguous fill                                  : {med['write, contiguous']:6.2f} ms")


# ---------------------------------------------------------------------------------------
# [2] a cached simulate process
# ---------------------------------------------------------------------------------------
def bench_process(rounds: int) -> None:
    env = dict(os.environ, PYTHONPATH=str(SRC))
    with tempfile.TemporaryDirectory() as tmp:
        Path(tmp, "numba_floor.py").write_text(_FLOOR_MODULE)
        floor_env = dict(env, PYTHONPATH=tmp, NUMBA_CACHE_DIR=str(Path(tmp, "cache")))
        kinds = {"python": ("pass", env), "numpy": ("import numpy", env), "numba": ("import numba", env),
                 "scipy.linalg": ("import scipy.linalg", env), "floor": ("import numba_floor", floor_env),
                 "typer": ("import typer.main, typer._adapters", env), "pandas": ("import pandas", env)}
        for code, kenv in kinds.values():
            _process_s(code, kenv, repeat=1)  # caches and bytecode filled, not counted
        times = _rounds({k: (lambda c=c, e=e: _process_s(c, e, repeat=1)) for k, (c, e) in kinds.items()}, rounds)
    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"\n[2] whole processes (goal: a cached simulate <= 1 s); medians of {rounds} rounds")
    print(f"    python -c pass                    : {med['python']:5.2f} s")
    print(f"    import numpy                      : {med['numpy']:5.2f} s")
    print(f"    import numba                      : {med['numba']:5.2f} s")
    print(f"    import scipy.linalg               : {med['scipy.linalg']:5.2f} s   (numba's registries import it "
          "at the first compiled call)")
    print(f"    numba's floor                     : {med['floor']:5.2f} s   (a cached one-line function called "
          f"once; RATIO to import numba {_ratio(times, 'floor', 'numba'):.2f}x)")
    print(f"    import typer's command machinery  : {med['typer']:5.2f} s   (typer 0.29 imports pydantic with it)")
    print(f"    import pandas                     : {med['pandas']:5.2f} s   (pyarrow imports it to build any "
          "table: a sweep's client writes its parts with it)")


# ---------------------------------------------------------------------------------------
# [3] 1,000 sweep runs
# ---------------------------------------------------------------------------------------
_WORK = f"""import sys
sys.path[:0] = [{str(SRC)!r}, {str(HERE)!r}]
from bench_scale import _serial_per_run_s
print(_serial_per_run_s(120))
"""

_SWEEP_TOML = """[base]
scenario = "fig15-cooperative-v1"
method = "exponential"
dt_s = 0.005
pwm = "averaged"

[vary.K_P_per_rad]
start = 2000.0
stop = 4000.0
num = 2
"""


def _work_s() -> float:
    """One worker's work per run (bench_scale's), in a process of its own."""
    out = subprocess.run([sys.executable, "-c", _WORK], env=dict(os.environ, SMAFINGER_ENGINE="compiled"),
                         check=True, capture_output=True, text=True).stdout
    return float(out.strip().splitlines()[-1])


def _sweep_s(toml: Path) -> float:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env.update(PYTHONPATH=str(SRC), SMAFINGER_ENGINE="compiled")
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "smafinger.cli", "sweep", str(toml), "--out",
                        str(Path(out, "r.parquet"))], check=True, env=env, capture_output=True)
        return time.perf_counter() - t0


def bench_sweep(rounds: int, n_runs: int = 1000) -> None:
    cores = os.cpu_count() or 1
    with tempfile.TemporaryDirectory() as tmp:
        toml = Path(tmp, "two.toml")
        toml.write_text(_SWEEP_TOML)
        _sweep_s(toml)  # caches and bytecode filled, not counted
        times = _rounds({"work": _work_s, "fixed": lambda: _sweep_s(toml)}, rounds)
    med = {k: statistics.median(v) for k, v in times.items()}
    bound = med["fixed"] + n_runs * med["work"] / cores
    print(f"\n[3] {n_runs:,} full-cycle sweep runs (60 s, the long step) on {cores} cores (goal: <= 5 s); medians of "
          f"{rounds} rounds")
    print(f"    one worker's work per run, alone  : {1e3 * med['work']:6.2f} ms (min {1e3 * min(times['work']):.2f})")
    print(f"    a 2-run smafinger sweep process   : {med['fixed']:6.2f} s (the fixed cost; "
          f"min {min(times['fixed']):.2f})")
    print(f"    bound: fixed + {n_runs:,} x work / {cores} cores = {bound:.1f} s (goal 5 s; the cores' slowing of "
          "each other not counted: bench_scale.py [1])")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--only", nargs="+", choices=SECTIONS, default=list(SECTIONS))
    a = ap.parse_args()
    print(f"bench_floors: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} (1 min)")
    if "loop" in a.only:
        bench_loop(a.rounds)
    if "process" in a.only:
        bench_process(a.rounds)
    if "sweep" in a.only:
        bench_sweep(a.rounds)


if __name__ == "__main__":
    main()
