"""Speed and accuracy of the engine's settings (issue 11): a script printing ratios, not a timed test.

For each case, in one process, measured interleaved (so that load from elsewhere hits every
setting alike) and printed as ratios:

- ``reference``: rk4, 1 ms, the PWM resolved at its edges: the engine's default before the
  long-step default, what the paper's scenarios use, and the baseline of the ratios;
- ``long``: the long-step setting (exponential integrator, 5 ms, PWM averaged over its
  period, reach events located inside steps) and a few neighbours;
- ``edge``: the same integrator and step with the PWM resolved at its edges (a sub-step at
  every edge and output sample);
- ``(default)`` marks the setting a run of the case gets when it sets none of ``dt_s``,
  ``method``, ``pwm`` (``engine.numerics``: the long step for ``paper2010`` and
  ``authors2020``'s mechanics with the memory rule; the edge step for ``authors2020`` with its
  own rule; for the linear rig the semi-implicit long step in open loop, the reference in closed
  loop, where it has not converged);
- the error of each against a reference run (rk4, 1 us, exact PWM edges): RMS and max of the
  coordinate on the output grid, and the reach times.

Cases: the paper's co-operative full cycle (Fig. 15, -40 -> -25 -> -55 -> -40 deg, 45 s,
``paper2010``); the linear bias-spring rig's closed-loop cycle (10 mm, then 4 mm, 30 s);
the authors' 2020 profile 2 (``authors2020``, independent, 20 s). Then the authors' solver
(``authors-ode4``): the peak wire temperatures of their profiles 1 and 2 against their plots.

Then the legacy engine (smafinger 0.1, commit ff21ad0, before the engine redesign): with
``--legacy-src PATH`` (its ``src`` folder, e.g. from ``git worktree add /tmp/old ff21ad0``)
measured here, interleaved with this engine, on the full cycle (CPU time of the whole
``run_spec`` call, best of the repeats); without it, as recorded on this kind of machine; the SciPy baseline (the test oracle's ``solve_ivp``, open loop: it has no
controller), and the process-level times: ``smafinger --help``, a cached ``simulate`` (whole
process) and, with ``--cold``, the first result after a fresh install (an empty numba cache:
interpreted, while the kernel compiles in the background, :mod:`smafinger.engine.interpreted`),
against compiling first.

Usage::

    PYTHONPATH=src python benchmarks/bench_speed.py [--repeat 7] [--ref-dt 1e-6] [--cold] [--legacy-src PATH]
                                                    [--only process] [--case TEXT]

Goals (issue 11): full cycle <= 2 ms engine loop at <= 0.05 deg RMS and <= 0.3 deg max error;
``--help`` <= 0.3 s; cached ``simulate`` process <= 1 s; first result <= 10 s.
"""

from __future__ import annotations

import argparse
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
sys.path.insert(0, str(HERE.parent / "tests"))

from smafinger.engine.run import make_spec, run_spec  # noqa: E402
from smafinger.parameters import get  # noqa: E402

from oracle import simulate_baseline  # noqa: E402

#: (label, params, strategy, profile or open-loop program (keywords), t_end_s)
CASES = (
    ("paper2010 co-operative full cycle", "paper2010", "cooperative", "0:-25,reach:-55,reach:-40", 45.0),
    ("linear bias-spring rig, closed loop", "linear-bias-spring", "cooperative", "0:0.010,15:0.004", 30.0),
    # 45 s: through the wire's return to martensite, which the long step missed (0.126 mm RMS, 0.91 mm max)
    # until its stiffness was taken on the side the slider moves to (integrators.implicit_load)
    ("linear bias-spring rig, open loop", "linear-bias-spring", "open-loop",
     dict(voltage="0:0.6,6:0,12:0.4,18:0", drive="duty"), 45.0),
    ("authors2020 profile 2", "authors2020", "independent", "0:-25:upper,5:-55:both", 20.0),
    ("authors2020 with the memory rule, open loop", "authors2020+memory", "open-loop",
     dict(voltage="0:8:0,4:0:0,8:0:8,12:0:0"), 16.0),
)
TODAY = ("rk4", 1e-3, "exact")  # the reference numerics (engine.numerics.REFERENCE)
FAST = ("exponential", 5e-3, "averaged")  # the long step (engine.numerics.LONG_STEP)
EDGE = ("exponential", 5e-3, "exact")  # the edge step (engine.numerics.EDGE_STEP): the PWM resolved
SETTINGS = (TODAY, FAST, EDGE, ("semi-implicit", 5e-3, "averaged"), ("exponential", 1e-2, "averaged"),
            ("rk4", 1e-3, "averaged"), ("rk4", 1e-4, "exact"))

#: the legacy engine (commit ff21ad0), co-operative full cycle at rk4 / 1 ms, CPU time of run_spec,
#: measured on this kind of machine (2 cores) interleaved with this engine (--legacy-src)
LEGACY = {"kernel_ms": (15.2, 15.7), "rms_deg": 0.0056, "substeps": 83260}


def _params(name):
    """A named set; ``NAME+memory``: the set with the return-point-memory hysteresis."""
    base, _, rule = name.partition("+")
    return get(base).replace(hysteresis=rule) if rule else get(base)


def _spec(params, strategy, profile, t_end, setting=(None, None, None)):
    method, dt, pwm = setting
    run = profile if isinstance(profile, dict) else {"profile": profile}
    return make_spec(_params(params), strategy, t_end_s=t_end, dt_s=dt, method=method, pwm=pwm, **run)


def _coordinate(r):
    return r.theta_deg if r.spec.params.mechanism == "joint" else r.signal("position_m") * 1e3


def _errors(r, ref):
    e = _coordinate(r) - _coordinate(ref)
    return float(np.sqrt(np.mean(e ** 2))), float(np.max(np.abs(e)))


def _reached(r):
    return [None if s["reached_s"] is None else round(s["reached_s"], 4) for s in r.metrics["segments"]]


def bench_case(label, params, strategy, profile, t_end, repeat, ref_dt) -> dict:
    unit = "deg" if _params(params).mechanism == "joint" else "mm"
    specs, refused = {}, {}
    for s in SETTINGS:
        try:
            specs[s] = _spec(params, strategy, profile, t_end, s)
        except ValueError as exc:  # a step the slider's wire-slider mode makes unstable (numerics.unstable_step)
            refused[s] = str(exc)
    for sp in specs.values():
        run_spec(sp)  # compile or load the cache, outside the timing
    walls = {s: [] for s in specs}
    results = {}
    for _ in range(repeat):  # interleaved: every setting sees the same load
        for s, sp in specs.items():
            results[s] = run_spec(sp)
            walls[s].append(results[s].wall_s)
    t0 = time.perf_counter()
    ref = run_spec(_spec(params, strategy, profile, t_end, ("rk4", ref_dt, "exact")))
    t_ref = time.perf_counter() - t0
    print(f"\n== {label}: {params}, {strategy}, {profile!r}, {t_end:g} s simulated")
    print(f"   reference: rk4 {ref_dt * 1e6:g} us, exact PWM ({ref.substeps} sub-steps, {t_ref:.0f} s); "
          f"reached {_reached(ref)}")
    base = min(walls[TODAY])
    default = _spec(params, strategy, profile, t_end)
    default = (default.method, default.dt_s, default.pwm)
    out = {}
    for s in SETTINGS:
        tag = {TODAY: "reference", FAST: "long     ", EDGE: "edge     "}.get(s, "         ") + \
            (" (default)" if s == default else "          ")
        if s in refused:
            print(f"   {tag} {s[0]:13s} {s[1] * 1e3:4g} ms {s[2]:8s}: refused before the run: {refused[s]}")
            continue
        r = results[s]
        rms, mx = _errors(r, ref)
        best, med = min(walls[s]), statistics.median(walls[s])
        print(f"   {tag} {s[0]:13s} {s[1] * 1e3:4g} ms {s[2]:8s}: kernel {best * 1e3:7.2f} ms (median {med * 1e3:7.2f}), "
              f"{r.substeps:6d} sub-steps, RATIO reference/this {base / best:5.1f}x; "
              f"error RMS {rms:.4f} {unit}, max {mx:.4f} {unit}; reached {_reached(r)}")
        out[s] = {"best_s": best, "rms": rms, "max": mx}
    return out


#: one full cycle in a child process: CPU time of run_spec, best of N (argv: N, then NAME=VALUE
#: numerics; the legacy engine's make_spec takes the same names, and no pwm)
_CYCLE_CPU = """
import sys, time
from smafinger.engine.run import make_spec, run_spec
kw = {k: (float(v) if k == "dt_s" else v) for k, v in (a.split("=") for a in sys.argv[2:])}
spec = make_spec("paper2010", "cooperative", "0:-25,reach:-55,reach:-40", t_end_s=45.0, **kw)
run_spec(spec)
best = float("inf")
for _ in range(int(sys.argv[1])):
    t0 = time.thread_time()
    run_spec(spec)
    best = min(best, time.thread_time() - t0)
print(best * 1e3)
"""


def _cycle_cpu_ms(src: Path, repeat: int, *numerics: str) -> float:
    env = dict(os.environ, PYTHONPATH=str(src))
    out = subprocess.run([sys.executable, "-c", _CYCLE_CPU, str(repeat), *numerics], env=env, check=True,
                         capture_output=True, text=True).stdout
    return float(out.strip().splitlines()[-1])


def bench_legacy(paper: dict, legacy_src: Path | None, repeat: int) -> None:
    if legacy_src is None:
        fast, today = paper[FAST], paper[TODAY]
        lo, hi = LEGACY["kernel_ms"]
        print(f"\n== legacy engine (ff21ad0, recorded): co-operative full cycle rk4 1 ms: {lo:g}-{hi:g} ms, "
              f"{LEGACY['rms_deg']} deg RMS ({LEGACY['substeps']} sub-steps)")
        print(f"   RATIO legacy/long {lo / (fast['best_s'] * 1e3):.1f}-{hi / (fast['best_s'] * 1e3):.1f}x, "
              f"legacy/reference {lo / (today['best_s'] * 1e3):.2f}-{hi / (today['best_s'] * 1e3):.2f}x "
              "(recorded CPU times of the whole run_spec against this run's kernel-only times: not measured "
              "side by side; --legacy-src measures them)")
        return
    rows = {"legacy (ff21ad0) default: rk4 1 ms": (legacy_src,),
            "this engine, default (long step)": (SRC,),
            "this engine, reference: rk4 1 ms exact": (SRC, "dt_s=0.001")}
    times: dict = {k: [] for k in rows}
    for _ in range(3):  # interleaved rounds, each a fresh process per engine
        for k, (src, *numerics) in rows.items():
            times[k].append(_cycle_cpu_ms(src, repeat, *numerics))
    legacy = min(times[next(iter(rows))])
    print(f"\n== legacy engine measured here: co-operative full cycle, CPU of run_spec, best of {repeat} in each "
          "of 3 interleaved rounds")
    for k, ts in times.items():
        print(f"   {k:40s}: {min(ts):7.2f} ms (rounds {', '.join(f'{t:.2f}' for t in ts)}), "
              f"RATIO legacy/this {legacy / min(ts):5.2f}x")


def bench_scipy(repeat: int) -> None:
    """The open-loop case the SciPy baseline (tests/oracle) runs: upper wire at 8 V for 6 s, to 20 s."""
    p = get("paper2010").replace(minor_loop_reversal_C=0.0)
    voltage = "0:8:0,6:0:0"
    t_ref, th_ref, info_ref = simulate_baseline(p, voltage, method="LSODA", rtol=1e-10)
    _, _, info = simulate_baseline(p, voltage, method="RK45", rtol=1e-6)
    print(f"\n== SciPy baseline (tests/oracle, solve_ivp RK45 rtol 1e-6): open loop '{voltage}', 20 s: "
          f"{info['wall_s'] * 1e3:.0f} ms; reference LSODA rtol 1e-10")
    for s in (TODAY, FAST):
        sp = make_spec(p, "open-loop", voltage=voltage, t_end_s=20.0, dt_s=s[1], method=s[0], pwm=s[2],
                       output_interval_s=0.01)
        run_spec(sp)
        best = min(run_spec(sp).wall_s for _ in range(repeat))
        r = run_spec(sp)
        err = float(np.nanmax(np.abs(r.theta_deg - th_ref)))
        print(f"   {s[0]:13s} {s[1] * 1e3:g} ms {s[2]:8s}: kernel {best * 1e3:7.2f} ms, RATIO scipy/this "
              f"{info['wall_s'] / best:6.0f}x; max |dtheta| vs LSODA {err:.4f} deg")


#: the authors' 2020 profiles (paper/authors.py) and the published peak wire temperatures [degC]
#: read off their plots (gabrielegilardi/FingerControl, Example<n>_Results_SMA<k>); None: not known
AUTHORS_PROFILES = (
    (1, "0:-25:upper,5:-40:none,10:-30:upper", {"upper": None, "lower": None}),
    (2, "0:-25:upper,5:-55:both", {"upper": None, "lower": 135.0}),
)


def bench_authors() -> None:
    """Issue 10 section 4: peak wire temperatures, resolved PWM against the authors' solver."""
    print("\n== authors2020 peak wire temperatures (20 s): resolved PWM (rk4 1 ms exact) vs authors-ode4")
    for number, profile, published in AUTHORS_PROFILES:
        for method in ("rk4", "authors-ode4"):
            r = run_spec(make_spec("authors2020", "independent", profile, t_end_s=20.0, method=method))
            peaks = {w: float(np.max(r.signal(f"T_{w}_C"))) for w in published}
            shown = ", ".join(f"{w} {t:6.1f} degC" + ("" if published[w] is None else
                                                       f" (published {published[w]:g}, diff {t - published[w]:+.1f})")
                              for w, t in peaks.items())
            print(f"   profile {number} {method:13s}: {shown}")


def _process_s(code: str, env: dict | None = None, repeat: int = 3) -> float:
    """Best of ``repeat`` whole processes running ``code``. Python may write its bytecode
    (``PYTHONDONTWRITEBYTECODE`` is dropped): an installed package has it, so a process that
    compiles every module from source would not be what users run."""
    env = {k: v for k, v in (os.environ if env is None else env).items() if k != "PYTHONDONTWRITEBYTECODE"}
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True, env=env, capture_output=True)
        best = min(best, time.perf_counter() - t0)
    return best


#: numba's own start: a one-line function, cached, called once in a fresh process
_FLOOR_MODULE = """import numba


@numba.njit(cache=True, error_model="numpy")
def one(x):
    return x + 1.0


one(1.0)
"""

#: the command line of the cached full cycle (``smafinger simulate``)
_CLI_ARGV = "['smafinger', 'simulate', '--profile', '0:-25,reach:-55,reach:-40', '--t-end', '45', '--no-progress']"


def _process_kinds(env: dict, floor_dir: str) -> dict[str, tuple[str, dict]]:
    """The processes timed side by side: (code for ``python -c``, environment) by name.

    - ``api``: the cached full cycle through the Python API (``simulate(...)`` in ``python -c``);
    - ``command``: the same as the ``smafinger simulate`` command, through the console script,
      which freezes the collector before the process ends (``smafinger.cli._console``);
    - ``command, no freeze``: the command run and ended as before that (``sys.exit(main())``);
    - ``floor``: numba's own start, a cached one-line function (import numba, and its
      compiler's start, which a cached load needs: its registries import scipy.linalg to check
      for BLAS); ``floor, frozen``: the same ending as the command does.
    """
    compiled = dict(env, SMAFINGER_ENGINE="compiled")
    floor = dict(env, PYTHONPATH=floor_dir, NUMBA_CACHE_DIR=str(Path(floor_dir, "cache")))
    return {
        "help": ("import sys; sys.argv = ['smafinger', '--help']\nfrom smafinger.cli import _console\n"
                 "try:\n    _console()\nexcept SystemExit:\n    pass", env),
        "import": ("import smafinger", env),
        "api": ("from smafinger import simulate; simulate('paper2010', 'cooperative', "
                "'0:-25,reach:-55,reach:-40', t_end_s=45.0)", compiled),
        "command": (f"import sys\nsys.argv = {_CLI_ARGV}\nfrom smafinger.cli import _console\n_console()", compiled),
        "command, no freeze": (f"import sys\nsys.argv = {_CLI_ARGV}\nfrom smafinger.cli import main\n"
                               "sys.exit(main())", compiled),
        "floor": ("import numba_floor", floor),
        "floor, frozen": ("import numba_floor, gc; gc.freeze()", floor),
    }


def bench_process(cold: bool, rounds: int = 7) -> None:
    """Whole-process times, every kind once per round in turn (load from elsewhere hits each
    alike): medians over the rounds, and ratios as the median of the rounds' own ratios."""
    env = dict(os.environ, PYTHONPATH=str(SRC))
    with tempfile.TemporaryDirectory() as tmp:
        Path(tmp, "numba_floor.py").write_text(_FLOOR_MODULE)
        kinds = _process_kinds(env, tmp)
        for code, kenv in kinds.values():  # caches and bytecode filled, not counted
            _process_s(code, kenv, repeat=1)
        times: dict[str, list[float]] = {k: [] for k in kinds}
        for _ in range(rounds):
            for k, (code, kenv) in kinds.items():
                times[k].append(_process_s(code, kenv, repeat=1))
    med = {k: statistics.median(v) for k, v in times.items()}

    def ratio(a: str, b: str) -> float:
        return statistics.median(x / y for x, y in zip(times[a], times[b]))

    print(f"\n== process times (medians of {rounds} rounds, each kind once per round in turn; ratios: "
          "median of the rounds' ratios)")
    print(f"   smafinger --help             : {med['help']:6.2f} s   (goal <= 0.3 s; 'import smafinger' alone "
          f"{med['import']:.2f} s)")
    print(f"   cached simulate, full cycle  : {med['api']:6.2f} s   (goal <= 1 s; the Python API, python -c)")
    print(f"   ... smafinger simulate       : {med['command']:6.2f} s   (the command; RATIO command/API "
          f"{ratio('command', 'api'):.2f}x)")
    print(f"   ... without the freeze       : {med['command, no freeze']:6.2f} s   (the command ended by "
          f"sys.exit(main()), as before 3816f20; RATIO with/without {ratio('command', 'command, no freeze'):.2f}x)")
    print(f"   numba's floor                : {med['floor']:6.2f} s   (a cached one-line numba function, whole "
          f"process; {med['floor, frozen']:.2f} s ending as the command does)")
    print(f"   ... RATIO to the floor       : API {ratio('api', 'floor'):.2f}x "
          f"({med['api'] - med['floor']:+.2f} s), command {ratio('command', 'floor, frozen'):.2f}x "
          f"({med['command'] - med['floor, frozen']:+.2f} s)")
    if cold:
        bench_first_result(kinds["api"][0], env)


def bench_first_result(run: str, env: dict) -> None:
    """A fresh install (an empty numba cache): the first result (``auto``: interpreted while the
    kernel compiles in the background), the same forced to compile first, and when the
    background compile is done, the next run."""
    with tempfile.TemporaryDirectory() as tmp:
        env = {k: v for k, v in env.items() if k != "SMAFINGER_ENGINE"}
        t0 = time.perf_counter()
        first_s = _process_s(run, dict(env, NUMBA_CACHE_DIR=tmp), repeat=1)
        # numba writes the index, then the kernel's data file (atomically, by a rename)
        while not any(Path(tmp).rglob("kernel.run_kernel-*.nbc")) and time.perf_counter() - t0 < 900:
            time.sleep(0.5)
        ready_s = time.perf_counter() - t0
        after_s = _process_s(run, dict(env, NUMBA_CACHE_DIR=tmp), repeat=1)
    with tempfile.TemporaryDirectory() as tmp:
        compiled_s = _process_s(run, dict(env, NUMBA_CACHE_DIR=tmp, SMAFINGER_ENGINE="compiled"), repeat=1)
    print(f"   first result, empty cache    : {first_s:6.1f} s   (goal <= 10 s; interpreted, engine auto)")
    print(f"   ... compiled first instead   : {compiled_s:6.1f} s   ({compiled_s / first_s:.1f}x the auto first "
          "result; --engine compiled)")
    print(f"   ... kernel compiled (in the background) {ready_s:.1f} s after the first run began; "
          f"the run after it {after_s:.2f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--ref-dt", type=float, default=1e-6, help="reference step [s] (1e-6: minutes per case)")
    ap.add_argument("--cold", action="store_true", help="also time a run with an empty numba cache")
    ap.add_argument("--legacy-src", type=Path, default=None,
                    help="src folder of smafinger 0.1 (commit ff21ad0) to measure it side by side")
    ap.add_argument("--only", choices=("process",), default=None,
                    help="run only this section (process: the whole-process times)")
    ap.add_argument("--case", action="append", default=None, metavar="TEXT",
                    help="run only the cases whose label contains TEXT (repeatable), and nothing else")
    args = ap.parse_args()
    print(f"bench_speed: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} (1 min)")
    if args.only == "process":
        bench_process(args.cold, args.repeat)
        return
    if args.case:
        chosen = [c for c in CASES if any(text in c[0] for text in args.case)]
        if not chosen:
            ap.error(f"--case {args.case}: no case label contains it; the cases: {[c[0] for c in CASES]}")
        for c in chosen:
            bench_case(*c, repeat=args.repeat, ref_dt=args.ref_dt)
        return
    results = {c[0]: bench_case(*c, repeat=args.repeat, ref_dt=args.ref_dt) for c in CASES}
    bench_legacy(results[CASES[0][0]], args.legacy_src, args.repeat)
    bench_scipy(args.repeat)
    bench_authors()
    bench_process(args.cold, args.repeat)


if __name__ == "__main__":
    main()
