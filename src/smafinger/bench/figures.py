"""A figure per bench task, like the paper's: the coordinate against its target for every
controller (one column per strategy), and below it the hottest wire's temperature; and the
gain of the sine tasks against frequency, per mechanism.

Each figure is a job (:class:`TaskFigure`, :class:`BandwidthFigure`) that carries only the
runs it draws, so that a worker pool can draw them (:func:`task_figures`): drawing every
figure of the full bench took 20 s in one process.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
import pandas as pd

from .runner import BenchResult
from .scores import REPORT_SCALE
from .tasks import Task

#: figures are drawn from every n-th sample (the bench samples every 10 ms)
EVERY = 5


@dataclass(frozen=True)
class TaskFigure:
    """One task's figure: its runs' records, (mechanism, task, controller, strategy) -> RunRecord."""

    task: Task
    records: dict

    @property
    def runs(self) -> int:
        return len(self.records)

    def draw(self) -> tuple[str, bytes]:
        return task_figure(self.records, self.task)


@dataclass(frozen=True)
class BandwidthFigure:
    """One mechanism's sine gains: the bench rows of its sine tasks."""

    mechanism: str
    rows: pd.DataFrame
    tasks: tuple

    @property
    def runs(self) -> int:
        return len(self.rows)

    def draw(self) -> tuple[str, bytes]:
        return bandwidth_figure(self.rows, self.mechanism, self.tasks)


def _axes_label(rec) -> str:
    scale, unit = REPORT_SCALE[rec.unit]
    return f"{'angle' if rec.unit == 'deg' else 'position'} [{unit}]"


def task_figure(records: dict, task: Task):
    """(name, PNG bytes) of one task, from its runs' records ((mechanism, task, controller,
    strategy) -> RunRecord; others are ignored)."""
    import matplotlib.pyplot as plt  # on the caller's backend (the command line's: Agg, cli.main)

    keys = [k for k in records if k[0] == task.mechanism and k[1] == task.name]
    strategies = list(dict.fromkeys(k[3] for k in keys))
    controllers = list(dict.fromkeys(k[2] for k in keys))
    fig, axes = plt.subplots(2, len(strategies), figsize=(6.0 * len(strategies), 6.0), sharex=True, squeeze=False,
                             gridspec_kw={"height_ratios": (2, 1)})
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for j, strategy in enumerate(strategies):
        top, bottom = axes[0, j], axes[1, j]
        for i, label in enumerate(controllers):
            rec = records.get((task.mechanism, task.name, label, strategy))
            if rec is None:
                continue
            scale = REPORT_SCALE[rec.unit][0]
            t = rec.t[::EVERY]
            if i == 0:
                top.plot(t, rec.q_ref[::EVERY] * scale, "k--", lw=1.0, label=f"target ({label})")
            c = colours[i % len(colours)]
            top.plot(t, rec.q[::EVERY] * scale, color=c, lw=1.2, label=label)
            hottest = np.max(np.vstack([T[::EVERY] for T in rec.T_C.values()]), axis=0)
            bottom.plot(t, hottest, color=c, lw=1.0)
            top.set_ylabel(_axes_label(rec))
        top.set_title(f"{task.name}: {strategy}")
        bottom.set_ylabel("hottest wire [°C]")
        bottom.set_xlabel("time [s]")
        top.grid(alpha=0.3)
        bottom.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8, loc="best")
    fig.suptitle(task.description, fontsize=9)
    fig.tight_layout()
    return task_figure_name(task), png(fig)


def bandwidth_figure(rows: pd.DataFrame, mechanism: str, tasks: Sequence[Task]):
    """(name, PNG bytes): the fitted gain of every sine task against its frequency (log-log), from
    the bench's rows (:attr:`~.runner.BenchResult.rows`)."""
    import matplotlib.pyplot as plt  # on the caller's backend (the command line's: Agg, cli.main)

    freq = {t.name: t.frequency_hz for t in tasks if t.mechanism == mechanism and t.kind == "sine"}
    rows = rows[(rows["mechanism"] == mechanism) & (rows["task"].isin(list(freq)))]
    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    for (label, strategy), g in rows.groupby(["controller", "strategy"], sort=False):
        f = [freq[n] for n in g["task"]]
        ax.plot(f, g["gain"], "o-" if strategy == "cooperative" else "s--", label=f"{label} ({strategy})", lw=1.0)
    ax.axhline(1.0 / np.sqrt(2.0), color="k", lw=0.8, ls=":", label="-3 dB")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("gain (fitted amplitude / reference)")
    ax.set_title(f"{mechanism}: sine tracking")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return bandwidth_figure_name(mechanism), png(fig)


def task_figure_name(task: Task) -> str:
    """A task's figure's name (without ``.png``): ``MECHANISM-TASK``."""
    return f"{task.mechanism}-{task.name}"


def bandwidth_figure_name(mechanism: str) -> str:
    """A mechanism's sine gains' figure's name (without ``.png``)."""
    return f"{mechanism}-bandwidth"


def png(fig) -> bytes:
    """The figure as PNG bytes; the figure is closed."""
    import io

    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    return buf.getvalue()


def figure_jobs(res: BenchResult, tasks: Sequence[Task]) -> list:
    """Every task's figure and each mechanism's sine gains, as jobs, in the order they are written."""
    jobs: list = []
    for t in tasks:
        jobs.append(TaskFigure(t, {k: r for k, r in res.records.items() if k[0] == t.mechanism and k[1] == t.name}))
    for mech in dict.fromkeys(t.mechanism for t in tasks):
        if any(t.kind == "sine" and t.mechanism == mech for t in tasks):
            jobs.append(BandwidthFigure(mech, res.rows[res.rows["mechanism"] == mech], tuple(tasks)))
    return jobs


def draw(indexed_job: tuple[int, TaskFigure | BandwidthFigure]) -> tuple[int, str, bytes]:
    """Worker side of :func:`task_figures`: (index, name, PNG bytes) of one job."""
    i, job = indexed_job
    return (i, *job.draw())


def task_figures(res: BenchResult, tasks: Sequence[Task], pool=None,
                 on_progress: Callable[[int, int], None] | None = None) -> list[tuple[str, bytes]]:
    """(name, PNG bytes) of every task's figure and of each mechanism's sine gains, in that order;
    drawn on ``pool`` (:mod:`smafinger.engine.pools`) if given, else here.
    ``on_progress(done, total)``: after each figure."""
    jobs = figure_jobs(res, tasks)
    if pool is None or pool.slots == 1:
        outcomes = map(draw, enumerate(jobs))
    else:  # the figures with the most runs first: the pool stays busy to the end
        outcomes = pool.map_tasks(draw, sorted(enumerate(jobs), key=lambda ij: -ij[1].runs))
    drawn = {}
    for i, name, png_bytes in outcomes:
        drawn[i] = (name, png_bytes)
        if on_progress is not None:
            on_progress(len(drawn), len(jobs))
    return [drawn[i] for i in range(len(jobs))]
