"""``smafinger bench-controllers`` and ``smafinger tune``: compare controllers on one bench, tune gains.

Typer command functions, mounted by :mod:`smafinger.cli` (``app.command("bench-controllers")(
bench_controllers)``, ``app.command("tune")(tune)``); a small app of both is ``app`` here
(mounted in :mod:`smafinger.cli`: ``smafinger bench-controllers``, ``smafinger tune``).

Exit status: 0 done; 2 bad input (one line naming the option and the value, nothing written);
1 the runs could not complete (a worker pool broke).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import List, Optional

import typer

from .common import progress_display, progress_option

MECHANISMS = ("joint", "linear-bias-spring")


def _fail(msg: str, code: int = 2):
    first = str(msg).splitlines()[0] if str(msg) else "error"
    print(f"smafinger: error: {first}", file=sys.stderr)
    raise typer.Exit(code)


def _say(msg: str) -> None:
    print(msg, file=sys.stderr)


def _tasks(mechanisms: list[str], names: list[str], quick: bool = False):
    from ..bench.tasks import select_tasks

    try:
        return select_tasks(tuple(mechanisms or MECHANISMS), tuple(names or ()), quick)
    except ValueError as exc:
        _fail(f"--mechanism/--task: {exc}")


def bench_controllers(
    out: Path = typer.Option(..., "--out", "-o", help="folder for controllers.csv, controllers.md, bandwidth.csv, "
                                                       "goals.json and figures/ (created if needed; an earlier "
                                                       "bench's files there are replaced, other files refused)"),
    mechanism: List[str] = typer.Option([], "--mechanism", "-m", help=f"one of {', '.join(MECHANISMS)} "
                                                                      "(repeat; default: both)"),
    task: List[str] = typer.Option([], "--task", "-t", help="run only this task (repeat; default: every task)"),
    controller: List[str] = typer.Option([], "--controller", "-c", help="run only this controller (repeat)"),
    strategy: List[str] = typer.Option([], "--strategy", "-s", help="independent or cooperative (repeat; "
                                                                    "default: both)"),
    workers: Optional[int] = typer.Option(None, "--workers", "-w", help="local worker processes (default: "
                                                                        "every core; 1: no pool)"),
    figures: bool = typer.Option(True, "--figures/--no-figures", help="draw a figure per task"),
    quick: bool = typer.Option(False, "--quick", help="a smoke subset: a move per mechanism, the fastest sine, "
                                                      "the paper's PID and sliding mode (unless --controller)"),
    progress: Optional[bool] = progress_option("progress bars (runs, then figures)"),
):
    """Run every controller x strategy on the bench tasks; write the table, the goals and the figures.

    Tasks: the paper's Fig. 12/13 moves and Fig. 15 cycle, holds, a staircase and sine tracking
    (-3 dB bandwidth), on the joint and on the linear actuator (docs/controllers.md). The
    Markdown table is printed too.
    """
    from ..bench.presets import BENCH_CONTROLLERS, QUICK_CONTROLLERS
    from ..bench.report import markdown, own_files, write_report
    from ..bench.runner import STRATEGIES, run_bench
    from ..engine.batch import BatchError, make_pool
    from ..files import OutputError
    from ..outdir import check_out_dir

    bad = [c for c in controller if c not in BENCH_CONTROLLERS]
    if bad:
        _fail(f"--controller {bad[0]!r} is not one of {', '.join(BENCH_CONTROLLERS)}")
    bad = [s for s in strategy if s not in STRATEGIES]
    if bad:
        _fail(f"--strategy {bad[0]!r} is not one of {', '.join(STRATEGIES)}")
    if workers is not None and workers < 1:
        _fail(f"--workers {workers}: must be >= 1")
    try:  # before any run: a file, a missing parent, a folder holding files a bench does not write
        check_out_dir(out, own_files())
    except OutputError as exc:
        _fail(str(exc))
    tasks = _tasks(mechanism, task, quick)
    if not tasks:
        _fail("--mechanism/--task/--quick: no task left to run")
    labels = tuple(controller or (QUICK_CONTROLLERS if quick else BENCH_CONTROLLERS))
    written = False  # the outputs in place: a Ctrl-C from then on (the pool's and the display's
    # teardown, the printing) is not "no output was written" (found by review)
    try:
        # one pool for the runs and the figures; its workers start while the controllers are made
        with progress_display(progress) as display, make_pool(workers) as pool:
            try:
                res = run_bench(tasks, labels, tuple(strategy or STRATEGIES), workers, report=_say, pool=pool,
                                on_progress=display.counter("bench-controllers", "runs"))
            except BatchError as exc:
                _fail(str(exc), code=1)
            # all or nothing: staged inside --out, then replacing what an earlier bench wrote there
            write_report(res, tasks, out, figures=figures, pool=pool,
                         on_progress=display.counter("figures", "figures"))
            written = True
        print(markdown(res, tasks))
        _say(f"written to {out}")
    except KeyboardInterrupt:
        if written:
            raise KeyboardInterrupt(f"interrupted (Ctrl-C) after the outputs were written to {out}") from None
        raise


def tune(
    controller: str = typer.Argument(..., help="controller to tune: pid, fuzzy-pid, sliding-mode, "
                                               "rapid-heating, resistance", show_default=False),
    task: List[str] = typer.Option(..., "--task", "-t", help="bench task to tune on (repeat: the mean of their "
                                                             "objectives)"),
    mechanism: str = typer.Option("joint", "--mechanism", "-m", help=f"one of {', '.join(MECHANISMS)}"),
    strategy: str = typer.Option("cooperative", "--strategy", "-s", help="independent or cooperative"),
    param: List[str] = typer.Option([], "--param", "-p", help="free field NAME=LO:HI or NAME=LO:HI:log (repeat; "
                                                              "default: the controller's gains)"),
    set_: List[str] = typer.Option([], "--set", help="fixed controller field NAME=VALUE (repeat)"),
    max_peak_temperature_c: Optional[float] = typer.Option(
        None, "--max-peak-temperature-c", help="hottest wire allowed [degC] (default: the paper's PID's peak on "
                                               "the same tasks)"),
    budget: int = typer.Option(120, "--budget", help="candidate runs of CMA-ES (each runs every task)"),
    popsize: int = typer.Option(10, "--popsize", help="candidates per generation (one batch)"),
    seed: int = typer.Option(1, "--seed", help="CMA-ES seed (a tuning is deterministic for a seed)"),
    workers: Optional[int] = typer.Option(None, "--workers", "-w", help="local worker processes"),
    out: Optional[Path] = typer.Option(None, "--out", "-o", help="write the result as JSON here"),
):
    """Tune a controller's gains on bench tasks with CMA-ES, the hottest wire constrained.

    The objective is the task's cycle time (cycle tasks) or RMS error (the others) relative to
    the paper's PWM-PID on the same task, plus penalties for unreached targets, interlock
    violations and heat above the limit (docs/controllers.md, "Tuning").
    """
    from ..bench.runner import STRATEGIES
    from ..bench.tune import MIN_BUDGET, MIN_POPSIZE, FreeParam, task_measure
    from ..bench.tune import tune as run_tune
    from ..control.params import CONTROLLERS, controller_from
    from ..engine.batch import BatchError
    from ..parameters import ParameterError

    if controller not in CONTROLLERS:
        _fail(f"controller {controller!r} is not one of {', '.join(CONTROLLERS)}")
    if mechanism not in MECHANISMS:
        _fail(f"--mechanism {mechanism!r} is not one of {', '.join(MECHANISMS)}")
    if strategy not in STRATEGIES:
        _fail(f"--strategy {strategy!r} is not one of {', '.join(STRATEGIES)}")
    for name, v, lo in (("--budget", budget, MIN_BUDGET), ("--popsize", popsize, MIN_POPSIZE)):
        if v < lo:
            _fail(f"{name} {v}: must be >= {lo}")
    if max_peak_temperature_c is not None and not math.isfinite(max_peak_temperature_c):
        _fail(f"--max-peak-temperature-c {max_peak_temperature_c}: must be a finite temperature in degC")
    if workers is not None and workers < 1:
        _fail(f"--workers {workers}: must be >= 1")
    if out is not None:  # refused before the tuning, not after it
        from ..files import check_output

        check_output(out, "--out")
    tasks = _tasks([mechanism], task)
    try:
        free = [FreeParam.parse(x) for x in param] or None
        base = controller_from(controller, set_)
        res = run_tune(base, tasks, strategy, free, max_peak_temperature_c, budget, popsize, seed, workers,
                       report=_say, fixed=[a.split("=", 1)[0].strip() for a in set_])
    except (ValueError, ParameterError) as exc:
        _fail(str(exc))
    except BatchError as exc:
        _fail(str(exc), code=1)
    doc = {"controller": controller, "mechanism": mechanism, "strategy": strategy,
           "tasks": [t.name for t in tasks], "values": res.values, "fixed": list(set_),
           "objective": res.objective, "evaluations": res.evaluations, "max_peak_T_C": res.max_peak_T_C,
           "scores": res.scores, "reference": res.reference, "history": res.history,
           "command": "smafinger tune " + " ".join(sys.argv[2:] if len(sys.argv) > 2 else [controller])}
    if out is not None:  # before anything is printed: a closed stdout must not lose the gains
        from ..files import atomic_write_text, json_text

        atomic_write_text(out, json_text(doc, digits=None))  # strict JSON: a non-finite number as null
    for t, s, r in zip(tasks, res.scores, res.reference):
        print(f"{t.name}: {task_measure(t, s):.4g} (paper's PID {task_measure(t, r):.4g}), "
              f"peak {s['peak_T_C']:.1f} degC (limit {res.max_peak_T_C:.1f}), "
              f"{s['interlock_violations']} interlock violations")
    print("values: " + ", ".join(f"{k}={v:.6g}" for k, v in res.values.items()))
