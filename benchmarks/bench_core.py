"""Speed and accuracy of the engine on the co-operative full cycle (issue 2's goal).

Prints the warm wall time of the co-operative full cycle -40 -> -25 -> -55 -> -40 (45 s
simulated) at the reference numerics (rk4, 1 ms, exact PWM: the default before the
long-step default of docs/speed.md, whose figures benchmarks/bench_speed.py prints), and its
error (RMS and max, deg) against a 1 us reference run; the goal is <= 50 ms on one core with
<= 0.05 deg RMS. Run: ``python benchmarks/bench_core.py``. Also prints both integrators at 2,
1 and 0.5 ms (best of 3), to show why the reference is what it is.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from smafinger.engine.run import DEFAULT_DT_S, DEFAULT_METHOD, make_spec, run_spec

PROFILE = "0:-25,reach:-55,reach:-40"


def spec(dt_s, method=DEFAULT_METHOD, params="paper2010"):
    return make_spec(params, "cooperative", PROFILE, t_end_s=45.0, dt_s=dt_s, method=method)


def main() -> None:
    default = spec(DEFAULT_DT_S)
    run_spec(default)  # compile (or load the cache)
    walls = []
    for _ in range(7):
        r = run_spec(default)
        walls.append(r.wall_s)
    t0 = time.perf_counter()
    ref = run_spec(spec(1e-6))
    t_ref = time.perf_counter() - t0
    print(f"co-operative full cycle, 45 s simulated, paper2010, reference {DEFAULT_METHOD}, dt = {1e3 * DEFAULT_DT_S:g} ms")
    print(f"  wall (kernel only, warm): median {1e3 * statistics.median(walls):.1f} ms, min {1e3 * min(walls):.1f} ms "
          f"({r.substeps} sub-steps)   goal <= 50 ms")
    err = r.theta_deg - ref.theta_deg
    print(f"  error vs 1 us reference: RMS {np.sqrt(np.mean(err**2)):.4f} deg, max {np.max(np.abs(err)):.4f} deg   goal RMS <= 0.05")
    print(f"  reference run: {t_ref:.1f} s wall, {ref.substeps} sub-steps; speed-up {t_ref / statistics.median(walls):.0f}x")
    for dt in (2e-3, 1e-3, 5e-4):
        for method in ("rk4", "euler"):
            run_spec(spec(dt, method))
            rr = min((run_spec(spec(dt, method)) for _ in range(3)), key=lambda x: x.wall_s)
            e = rr.theta_deg - ref.theta_deg
            print(f"  {method:5s} dt = {1e3 * dt:.1f} ms: wall {1e3 * rr.wall_s:6.1f} ms, RMS {np.sqrt(np.mean(e**2)):.4f} deg, "
                  f"max {np.max(np.abs(e)):.4f} deg")
    segs = [s["reached_s"] for s in r.metrics["segments"]]
    segs_ref = [s["reached_s"] for s in ref.metrics["segments"]]
    print(f"  reached_s per segment: default {segs}, reference {segs_ref}")


if __name__ == "__main__":
    main()
