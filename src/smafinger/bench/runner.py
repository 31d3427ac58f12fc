"""Run the controller bench: every controller x strategy x task, on the batch engine.

:func:`run_bench` returns a :class:`BenchResult`: one row per run (:mod:`.scores`), the -3 dB
bandwidth per controller and strategy (from the sine tasks) and the runs' records (for the
figures). Runs are independent and deterministic, so the table does not depend on the number
of workers.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Callable, Sequence

import pandas as pd

from ..engine.batch import run_batch
from ..engine.defaults import DEFAULT_DT_S, DEFAULT_METHOD, DEFAULT_PWM
from ..engine.run import make_spec
from ..values import one_or_many
from .presets import BENCH_CONTROLLERS, bench_controller
from .scores import RunRecord, bandwidth, record_of, task_scores
from .tasks import Task

STRATEGIES = ("independent", "cooperative")
#: the bench samples its runs this often [s] (reach times are decided by the engine at every step)
OUTPUT_S = 0.01
#: every controller runs at the reference numerics (engine.numerics), whatever a run's default:
#: the laws were tuned and are scored on the resolved PWM, and all compare on the same numerics
BENCH_NUMERICS = MappingProxyType({"dt_s": DEFAULT_DT_S, "method": DEFAULT_METHOD, "pwm": DEFAULT_PWM})


@dataclass
class BenchResult:
    rows: pd.DataFrame  #: one row per run: mechanism, task, kind, controller, strategy, metrics
    bandwidth: pd.DataFrame  #: mechanism, controller, strategy, bandwidth_hz
    records: dict = field(default_factory=dict)  #: (mechanism, task, controller, strategy) -> RunRecord
    controllers: dict = field(default_factory=dict)  #: (mechanism, label) -> ControllerParameters


def bench_specs(tasks: Sequence[Task], controllers: dict, strategies: Sequence[str]) -> list[tuple[tuple, object]]:
    """((mechanism, task, controller, strategy), spec) for every combination; ``controllers`` maps
    (mechanism, label) to a controller object."""
    out = []
    for task in tasks:
        p = task.params()
        for (mech, label), ctrl in controllers.items():
            if mech != task.mechanism:
                continue
            for strategy in strategies:
                spec = make_spec(p, strategy, task.profile, t_end_s=task.t_end_s, output_interval_s=OUTPUT_S,
                                 controller=ctrl, **BENCH_NUMERICS)
                out.append(((task.mechanism, task.name, label, strategy), spec))
    return out


def run_bench(tasks: Sequence[Task], labels: Sequence[str] = BENCH_CONTROLLERS,
              strategies: Sequence[str] = STRATEGIES, workers: int | None = None,
              report: Callable[[str], None] | None = None, controllers: dict | None = None,
              pool=None, on_progress: Callable[[int, int], None] | None = None) -> BenchResult:
    """Run every controller (``labels``, as :func:`~.presets.bench_controller` sets them, or
    ``controllers``: (mechanism, label) -> object) under every strategy on every task; on
    ``pool`` (:mod:`smafinger.engine.pools`) if given, else on ``workers`` processes.
    ``on_progress(done, total)``: as the runs finish (:func:`~smafinger.engine.batch.run_batch`)."""
    say = report or (lambda msg: None)
    labels, strategies = one_or_many(labels), one_or_many(strategies)
    bad = [s for s in strategies if s not in STRATEGIES]
    if bad:
        raise ValueError(f"strategy {bad[0]!r} is not one of {', '.join(STRATEGIES)}")
    if controllers is None:
        controllers = {}
        for mech in dict.fromkeys(t.mechanism for t in tasks):
            p = next(t for t in tasks if t.mechanism == mech).params()
            for label in labels:
                if label == "resistance":
                    say(f"calibrating the self-sensing controller on {p.name}")
                ctrl = bench_controller(label, p)
                if ctrl is not None:
                    controllers[(mech, label)] = ctrl
    keyed = bench_specs(tasks, controllers, strategies)
    warm_kernels(spec for _, spec in keyed)
    say(f"{len(keyed)} runs: {len(tasks)} tasks, {len(labels)} controllers (tuned entries on their own mechanism "
        f"only), {len(strategies)} strategies")
    outcomes = run_batch([spec for _, spec in keyed], workers=workers, reduce=record_of, pool=pool,
                         on_progress=on_progress)
    by_name = {(t.mechanism, t.name): t for t in tasks}
    rows, records = [], {}
    for (mech, task_name, label, strategy), rec in zip((k for k, _ in keyed), outcomes):
        task = by_name[(mech, task_name)]
        records[(mech, task_name, label, strategy)] = rec
        rows.append({"mechanism": mech, "task": task_name, "kind": task.kind, "controller": label,
                     "strategy": strategy, **task_scores(task, rec)})
    table = pd.DataFrame(rows)
    return BenchResult(table, bandwidth_table(table, tasks), records, controllers)


def warm_kernels(specs) -> None:
    """Compile (or load) the loop once here for each kind of run among ``specs`` (mechanism and
    controller record type), so that the workers load it from numba's cache instead of each
    compiling it at once."""
    from ..engine.run import compile_kernel, kernel_key

    seen = set()
    for spec in specs:
        key = kernel_key(spec)
        if key not in seen:
            seen.add(key)
            compile_kernel(spec)


def bandwidth_table(rows: pd.DataFrame, tasks: Sequence[Task]) -> pd.DataFrame:
    """The -3 dB bandwidth of each (mechanism, controller, strategy) from its sine tasks."""
    freq = {(t.mechanism, t.name): t.frequency_hz for t in tasks if t.kind == "sine"}
    out = []
    if rows.empty or "gain" not in rows:
        return pd.DataFrame(columns=["mechanism", "controller", "strategy", "bandwidth_hz", "bound", "below_hz",
                                     "above_hz"])
    sines = rows[rows["kind"] == "sine"]
    for (mech, label, strategy), g in sines.groupby(["mechanism", "controller", "strategy"], sort=False):
        fs = [freq[(mech, n)] for n in g["task"]]
        bw = bandwidth(fs, list(g["gain"]))
        # "<=": already below -3 dB at the lowest frequency tried (below_hz); ">": never below (above the
        # highest, above_hz); "between": in (below_hz, above_hz), the run at above_hz did not move
        low, high = (bw.low_hz, bw.high_hz) if bw.bound == "between" else (min(fs), max(fs))
        out.append({"mechanism": mech, "controller": label, "strategy": strategy, "bandwidth_hz": bw.hz,
                    "bound": bw.bound, "below_hz": low, "above_hz": high})
    return pd.DataFrame(out)


__all__ = ["BenchResult", "run_bench", "bench_specs", "bandwidth_table", "STRATEGIES", "RunRecord"]
