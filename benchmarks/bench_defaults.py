"""Where each default numerics setting holds (engine.numerics): a script printing errors and
ratios, not a timed test.

For runs beyond the paper's joint under its PID (other hysteresis rules, PWM periods,
controllers, the authors' 2020 model), it prints, side by side
in one process (interleaved, best of ``--repeat``), the reference (rk4, 1 ms, exact PWM), the
edge step (exponential, 5 ms, exact PWM: a sub-step at every edge and output sample) and the
long step, each with its error against rk4 at 0.1 ms with exact PWM edges (RMS and max of
theta on the 1 ms output grid, and the largest difference of a reach time), and which of them
the run gets by default. The cases: the authors' 2020 model with its own hysteresis rule,
paper2010 with that rule and the dead-band one, longer PWM periods, and the closed-loop
controllers, on the co-operative full cycle (-40 -> -25 -> -55 -> -40 deg, 45 s), the
independent one, and an open-loop program that switches every 0.3 s.

Usage::

    PYTHONPATH=src python benchmarks/bench_defaults.py [--repeat 3] [--only NAME ...]
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "src"))

from smafinger.bench.presets import bench_controller  # noqa: E402
from smafinger.control.params import PaperPID, SlidingModeParameters  # noqa: E402
from smafinger.engine.run import make_spec, run_spec  # noqa: E402
from smafinger.parameters import get  # noqa: E402

CYCLE = "0:-25,reach:-55,reach:-40"
COOP = dict(strategy="cooperative", profile=CYCLE, t_end_s=45.0)
IND = dict(strategy="independent", profile=CYCLE, t_end_s=45.0)
PROGRAM = dict(strategy="open-loop", t_end_s=20.0,
               voltage="0:8:0,3:0:0,6:0:8,9:0:0,12:8:0,12.3:0:8,12.6:8:0,12.9:0:0")


def _p(**changes):
    return get("paper2010").replace(**changes)


#: name -> make_spec keywords (params, controller and the run)
CASES = {
    "authors2020 profile 1": dict(params="authors2020", strategy="independent", profile="0:-25:upper", t_end_s=20.0),
    "authors2020 profile 2": dict(params="authors2020", strategy="independent", profile="0:-25:upper,5:-55:both",
                                  t_end_s=20.0),
    "authors2020 full cycle": dict(params="authors2020", **COOP),
    "authors2020 full cycle, independent": dict(params="authors2020", **IND),
    "authors2020 program": dict(params="authors2020", **PROGRAM),
    "authors2020 rapid-heating": dict(params="authors2020", controller="rapid-heating", **COOP),
    "authors2020 with the memory rule, full cycle": dict(params=get("authors2020").replace(hysteresis="memory"),
                                                         **COOP),
    "paper2010 authors' rule": dict(params=_p(hysteresis="authors2020"), **COOP),
    "paper2010 authors' rule, independent": dict(params=_p(hysteresis="authors2020"), **IND),
    "paper2010 authors' rule, program": dict(params=_p(hysteresis="authors2020"), **PROGRAM),
    "paper2010 dead-band": dict(params=_p(hysteresis="deadband"), **COOP),
    "paper2010 dead-band, independent": dict(params=_p(hysteresis="deadband"), **IND),
    "paper2010 PWM 10 ms, independent": dict(params=_p(pwm_period_s=0.01), **IND),
    "paper2010 PWM 20 ms": dict(params=_p(pwm_period_s=0.02), **COOP),
    "paper2010 PWM 20 ms, program": dict(params=_p(pwm_period_s=0.02), **PROGRAM),
    "paper2010 PWM 50 ms": dict(params=_p(pwm_period_s=0.05), **COOP),
    "pid, the bench's tuning": dict(params="paper2010", **COOP,
                                    controller=bench_controller("pid-tuned", get("paper2010"))),
    "pid, K_V 300": dict(params="paper2010", **COOP, controller=PaperPID(K_V_s_per_q=300.0)),
    "sliding-mode": dict(params="paper2010", controller="sliding-mode", **COOP),
    "sliding-mode, independent": dict(params="paper2010", controller="sliding-mode", **IND),
    "sliding-mode, the bench's tuning": dict(params="paper2010", **COOP,
                                             controller=bench_controller("sliding-mode-tuned", get("paper2010"))),
    "sliding-mode, the bench's tuning, independent": dict(params="paper2010", **IND, controller=bench_controller(
        "sliding-mode-tuned", get("paper2010"))),
    "sliding-mode, boundary layer 0.01 rad/s": dict(params="paper2010", controller=SlidingModeParameters(
        phi_q_per_s=0.01), **COOP),
    "sliding-mode, K 50 %, independent": dict(params="paper2010", controller=SlidingModeParameters(K_pct=50.0), **IND),
    "sliding-mode, paper2010-table2, scheduled": dict(params="paper2010-table2", controller="sliding-mode",
                                                      strategy="cooperative", profile="0:-25,6:-55,12:-40,18:-30",
                                                      t_end_s=24.0),
    "authors2020 sliding-mode, boundary layer 0.01 rad/s": dict(params="authors2020", controller=SlidingModeParameters(
        phi_q_per_s=0.01), **COOP),
    "rapid-heating": dict(params="paper2010", controller="rapid-heating", **COOP),
    "rapid-heating, the bench's tuning": dict(params="paper2010", **COOP,
                                              controller=bench_controller("rapid-heating-tuned", get("paper2010"))),
    "rapid-heating, independent": dict(params="paper2010", controller="rapid-heating", **IND),
    "fuzzy-pid": dict(params="paper2010", controller="fuzzy-pid", **COOP),
    "fuzzy-pid, independent": dict(params="paper2010", controller="fuzzy-pid", **IND),
    "resistance": dict(params="paper2010", controller="resistance", **COOP),
    "whole-wire heating": dict(params=get("paper2010-table2").replace(joule_heating="whole-wire"), **COOP),
}
SETTINGS = {"reference": ("rk4", 1e-3, "exact"), "edge": ("exponential", 5e-3, "exact"),
            "long": ("exponential", 5e-3, "averaged")}
TRUTH = ("rk4", 1e-4, "exact")


def _spec(kw, setting=(None, None, None)):
    method, dt, pwm = setting
    return make_spec(**kw, method=method, dt_s=dt, pwm=pwm)


def _reach_diff(r, ref):
    worst = 0.0
    for a, b in zip(r.metrics["segments"], ref.metrics["segments"]):
        if (a["reached_s"] is None) != (b["reached_s"] is None):
            return float("inf")
        if a["reached_s"] is not None:
            worst = max(worst, abs(a["reached_s"] - b["reached_s"]))
    return worst


def bench(name, kw, repeat) -> dict:
    truth = run_spec(_spec(kw, TRUTH))
    specs = {k: _spec(kw, s) for k, s in SETTINGS.items()}
    default = _spec(kw)
    default = next((k for k, s in SETTINGS.items() if s == (default.method, default.dt_s, default.pwm)), "?")
    walls = {k: [] for k in specs}
    results = {k: run_spec(sp) for k, sp in specs.items()}  # compiled or loaded outside the timing
    for _ in range(repeat):
        for k, sp in specs.items():
            walls[k].append(run_spec(sp).wall_s)
    base = min(walls["reference"])
    print(f"\n== {name} (default: {default})")
    out = {}
    for k, r in results.items():
        e = r.theta_deg - truth.theta_deg
        rms, mx = float(np.sqrt(np.mean(e ** 2))), float(np.max(np.abs(e)))
        best = min(walls[k])
        method, dt, pwm = SETTINGS[k]
        print(f"   {k:9s} {method:11s} {dt * 1e3:g} ms {pwm:8s}: kernel {best * 1e3:7.2f} ms, "
              f"RATIO reference/this {base / best:4.1f}x; error RMS {rms:.4f} deg, max {mx:.3f} deg, "
              f"reach {_reach_diff(r, truth):.3f} s")
        out[k] = (rms, mx, base / best)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", nargs="*", default=None, help="case names (default: all)")
    a = ap.parse_args()
    print(f"bench_defaults: {os.cpu_count()} cpus, load average {os.getloadavg()[0]:.2f}; truth: rk4 0.1 ms, exact PWM")
    for name, kw in CASES.items():
        if a.only is None or name in a.only:
            bench(name, kw, a.repeat)


if __name__ == "__main__":
    main()
