"""This engine against another commit's, side by side: a script printing ratios, not a timed test.

The co-operative full cycle (Fig. 15, -40 -> -25 -> -55 -> -40 deg, 45 s simulated,
``paper2010``) at the default numerics, in two forms:

- ``step loop``: only the metrics' signals recorded, a sample every 5 ms (the loop's own work);
- ``default``: every signal, a sample every 1 ms (what ``simulate`` does).

Each round runs one process on this checkout's ``src`` and one on the other's, in turn, each
timing ``runs`` runs of both forms (the kernel's wall time, ``SimulationResult.wall_s``). The
machine's speed drifts (on the shared 2-core machines it switches between two speeds for
seconds at a time), so the figures to read are the median over the rounds of each round's
ratio of medians, and the ratio of the best runs; each side's median and best are printed too.
The other checkout's numba cache is filled first, in a process not counted.

Usage::

    git worktree add /tmp/base <commit>   # or any copy of that commit's src
    PYTHONPATH=src python benchmarks/bench_ab.py --base-src /tmp/base/src [--rounds 20] [--runs 20]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src"

#: one process's share of a round: argv[1] runs of each form; prints {form: [wall_s, ...]}
_CHILD = """
import dataclasses, json, sys
from smafinger.engine.run import make_spec, run_spec
n = int(sys.argv[1])
spec = make_spec("paper2010", "cooperative", "0:-40,5:-25,20:-55,35:-40", t_end_s=45.0)
forms = {"step loop": (dataclasses.replace(spec, output_interval_s=0.005), "metrics"), "default": (spec, "all")}
out = {}
for name, (s, record) in forms.items():
    run_spec(s, record=record)
    out[name] = [run_spec(s, record=record).wall_s for _ in range(n)]
print(json.dumps(out))
"""

FORMS = {"step loop": "metrics only, a sample every 5 ms", "default": "every signal, a sample every 1 ms"}


def _child(src: Path, runs: int) -> dict[str, list[float]]:
    env = dict(os.environ, PYTHONPATH=str(src), SMAFINGER_ENGINE="compiled")
    out = subprocess.run([sys.executable, "-c", _CHILD, str(runs)], env=env, check=True, capture_output=True,
                         text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--base-src", type=Path, required=True, help="the other checkout's src folder")
    ap.add_argument("--rounds", type=int, default=20)
    ap.add_argument("--runs", type=int, default=20, help="runs of each form in each process")
    a = ap.parse_args()
    if not (a.base_src / "smafinger").is_dir():
        ap.error(f"--base-src {a.base_src}: no smafinger package in it")
    print(f"bench_ab: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} (1 min); this: {SRC}, "
          f"base: {a.base_src}")
    for src in (SRC, a.base_src):
        _child(src, 1)  # numba's cache filled, not counted
    meds = {side: {f: [] for f in FORMS} for side in ("this", "base")}
    bests = {side: {f: [] for f in FORMS} for side in ("this", "base")}
    for _ in range(a.rounds):
        for side, src in (("this", SRC), ("base", a.base_src)):
            for f, walls in _child(src, a.runs).items():
                meds[side][f].append(statistics.median(walls))
                bests[side][f].append(min(walls))
    print(f"\n== the co-operative full cycle (45 s), default numerics: {a.rounds} rounds, one process per side "
          f"in turn, {a.runs} runs of each form in each")
    for f, what in FORMS.items():
        ratios = [x / y for x, y in zip(meds["this"][f], meds["base"][f])]
        this_best, base_best = min(bests["this"][f]), min(bests["base"][f])
        print(f"   {f:9s} ({what}): this {statistics.median(meds['this'][f]) * 1e3:6.2f} ms (best "
              f"{this_best * 1e3:.2f}), base {statistics.median(meds['base'][f]) * 1e3:6.2f} ms (best "
              f"{base_best * 1e3:.2f}); RATIO this/base {statistics.median(ratios):.3f}x by the median of the "
              f"rounds (they spread {min(ratios):.2f}-{max(ratios):.2f}), {this_best / base_best:.3f}x by the bests")


if __name__ == "__main__":
    main()
