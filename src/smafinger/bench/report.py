"""The bench's outputs: the table (CSV with a ``controller`` column, and Markdown), the -3 dB
bandwidths, the issue's goals checked, and a figure per task (:mod:`.figures`).

Everything is computed before anything is written, and the files replace what an earlier bench
wrote in the folder all at once (:func:`smafinger.outdir.staged`, with the bench's own file
names, :func:`own_files`): no file of an earlier bench (a figure of a task not run this time)
stays beside the new ones, and a failure leaves the folder as it was.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Callable, Sequence

import pandas as pd

from ..outdir import OwnFiles, check_out_dir, staged
from .runner import BenchResult
from .tasks import ALL_TASKS, Task

#: the goals of issue 15 (checked by :func:`goals`)
SPEED_GAIN = 0.30  #: the best controller completes the Fig. 15 cycle at least this much faster
HOLD_TOLERANCE_DEG = 0.5  #: the resistance-only controller holds a target within this
#: columns of the Markdown tables: (column, header, format)
COLUMNS = (("rms_error", "RMS error", ".3g"), ("time_to_target_s", "to target [s]", ".2f"),
           ("cycle_s", "cycle [s]", ".2f"), ("unreached", "unreached", "d"), ("overshoot", "overshoot", ".3g"),
           ("settling_s", "settling [s]", ".2f"), ("limit_cycle", "limit cycle", ".3g"),
           ("hold_error", "hold error", ".3g"), ("gain", "gain", ".3f"), ("phase_deg", "phase [deg]", ".1f"),
           ("energy_J", "energy [J]", ".0f"), ("peak_T_C", "peak T [°C]", ".1f"),
           ("interlock_violations", "interlock", "d"))


def _fmt(v, spec: str) -> str:
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "—"
    return format(int(v), spec) if spec == "d" else format(float(v), spec)


def task_table(rows: pd.DataFrame) -> str:
    """One task's rows as a Markdown table (the columns it has values in)."""
    cols = [c for c in COLUMNS if c[0] in rows and rows[c[0]].notna().any()]
    unit = rows["unit"].iloc[0]
    head = ["controller", "strategy"] + [h if c not in ("rms_error", "overshoot", "limit_cycle", "hold_error")
                                         else f"{h} [{unit}]" for c, h, _ in cols]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for _, r in rows.iterrows():
        lines.append("| " + " | ".join([r["controller"], r["strategy"]] + [_fmt(r[c], f) for c, _, f in cols]) + " |")
    return "\n".join(lines)


def bandwidth_markdown(bw: pd.DataFrame) -> str:
    lines = ["| controller | strategy | -3 dB bandwidth [Hz] |", "|---|---|---|"]
    for _, r in bw.iterrows():
        shown = {">": f"> {r['above_hz']:g}", "<=": f"≤ {r['below_hz']:g}",
                 "between": f"{r['below_hz']:g}-{r['above_hz']:g}"}.get(r["bound"], f"{r['bandwidth_hz']:.3g}")
        lines.append(f"| {r['controller']} | {r['strategy']} | {shown} |")
    return "\n".join(lines)


def _row(rows: pd.DataFrame, **where) -> pd.DataFrame:
    m = pd.Series(True, index=rows.index)
    for k, v in where.items():
        m &= rows[k] == v
    return rows[m]


def goals(rows: pd.DataFrame) -> dict:
    """The issue's goals, measured (``None`` where the bench did not run what a goal needs)."""
    out: dict = {"speed": None, "self_sensing": None}
    cyc = _row(rows, mechanism="joint", task="fig15-cycle")
    ref = _row(cyc, controller="pid", strategy="cooperative")
    # measured only beside another controller: with the paper's PID alone nothing was compared
    if not ref.empty and ref["cycle_s"].notna().all() and (cyc["controller"] != "pid").any():
        r = ref.iloc[0]
        ok = cyc[cyc["cycle_s"].notna() & (cyc["interlock_violations"] == 0) & (cyc["peak_T_C"] <= r["peak_T_C"])]
        ok = ok[ok["controller"] != "pid"]
        best = ok.loc[ok["cycle_s"].idxmin()] if not ok.empty else None
        out["speed"] = {
            "reference": {"controller": "pid", "strategy": "cooperative", "cycle_s": float(r["cycle_s"]),
                          "peak_T_C": float(r["peak_T_C"])},
            "best": None if best is None else {
                "controller": best["controller"], "strategy": best["strategy"], "cycle_s": float(best["cycle_s"]),
                "peak_T_C": float(best["peak_T_C"]), "interlock_violations": int(best["interlock_violations"]),
                "faster": 1.0 - float(best["cycle_s"]) / float(r["cycle_s"])},
        }
        out["speed"]["met"] = best is not None and out["speed"]["best"]["faster"] >= SPEED_GAIN
    out["self_sensing"] = _self_sensing(rows)
    return out


def _self_sensing(rows: pd.DataFrame) -> dict | None:
    """The resistance controller's holds: met if every hold run reached its target and stayed
    within :data:`HOLD_TOLERANCE_DEG` of it, its mean (``hold_error``) and half its peak-to-peak
    (``limit_cycle``) alike. The hold error alone let a run that never reached its target and
    oscillated about it pass."""
    holds = _row(rows, mechanism="joint", controller="resistance")
    holds = holds[holds["task"].str.startswith("hold-")]
    if holds.empty:
        return None

    def number(v):
        return None if v is None or (isinstance(v, float) and math.isnan(v)) else float(v)

    per, unreached, cycles, held = {}, {}, {}, []
    for _, r in holds.iterrows():
        key = f"{r['task']}/{r['strategy']}"
        per[key], cycles[key], unreached[key] = number(r["hold_error"]), number(r["limit_cycle"]), int(r["unreached"])
        held.append(unreached[key] == 0 and per[key] is not None and per[key] <= HOLD_TOLERANCE_DEG
                    and cycles[key] is not None and cycles[key] / 2.0 <= HOLD_TOLERANCE_DEG)
    errs = [v for v in per.values() if v is not None]
    return {"hold_error_deg": per, "worst_deg": max(errs) if errs else None, "unreached": unreached,
            "limit_cycle_deg": cycles, "met": all(held)}


def goals_markdown(g: dict) -> str:
    lines = ["## Goals of issue 15", ""]
    s = g["speed"]
    if s is None:
        lines.append("- Fig. 15 speed goal: not measured (run the joint's fig15-cycle task with the pid controller "
                     "and another).")
    elif s["best"] is None:
        lines.append("- Fig. 15 speed goal: **not met**: no controller completed the cycle within the paper's "
                     f"co-operative PID's peak temperature ({s['reference']['peak_T_C']:.1f} °C) without interlock "
                     "violations.")
    else:
        b, r = s["best"], s["reference"]
        lines.append(f"- Fig. 15 speed goal (≥ {SPEED_GAIN:.0%} faster than the paper's co-operative PWM-PID, no "
                     f"hotter, 0 interlock violations): **{'met' if s['met'] else 'not met'}**. Paper's PID "
                     f"(co-operative): {r['cycle_s']:.2f} s, peak {r['peak_T_C']:.1f} °C; best: {b['controller']} "
                     f"({b['strategy']}) {b['cycle_s']:.2f} s ({b['faster']:.0%} faster), peak {b['peak_T_C']:.1f} "
                     f"°C, {b['interlock_violations']} interlock violations.")
    h = g["self_sensing"]
    if h is None:
        lines.append("- Self-sensing goal: not measured (run the joint's hold tasks with the resistance controller).")
    else:
        shown = ", ".join(f"{k} {'—' if v is None else f'{v:.2f}'} deg" for k, v in h["hold_error_deg"].items())
        lines.append(f"- Self-sensing goal (resistance alone holds a target within {HOLD_TOLERANCE_DEG:g} deg): "
                     f"**{'met' if h['met'] else 'not met'}**; hold errors: {shown}.")
    return "\n".join(lines)


def markdown(res: BenchResult, tasks: Sequence[Task]) -> str:
    """The whole report: goals, then per mechanism every task's table and the bandwidths."""
    parts = ["# Controller bench", "", goals_markdown(goals(res.rows)), ""]
    for mech in dict.fromkeys(t.mechanism for t in tasks):
        parts += [f"## {mech} ({tasks[[t.mechanism for t in tasks].index(mech)].params().name})", ""]
        used = {label: c for (m, label), c in res.controllers.items() if m == mech}
        parts += ["Controllers: " + "; ".join(f"`{label}` = {c.describe()}" for label, c in used.items()), ""]
        for t in (t for t in tasks if t.mechanism == mech):
            parts += [f"### {t.name}", "", t.description, "", task_table(_row(res.rows, mechanism=mech, task=t.name)), ""]
        bw = res.bandwidth[res.bandwidth["mechanism"] == mech] if not res.bandwidth.empty else res.bandwidth
        if not bw.empty:
            parts += ["### -3 dB bandwidth (sine tasks)", "", bandwidth_markdown(bw), ""]
    return "\n".join(parts)


#: the bench's files in its folder; its figures go to :data:`FIGURES_DIR`
TABLE_FILES = ("controllers.csv", "bandwidth.csv", "controllers.md", "goals.json")
FIGURES_DIR = "figures"


def figure_names(tasks: Sequence[Task] = ALL_TASKS) -> frozenset[str]:
    """The PNG names :mod:`.figures` gives ``tasks``' figures: ``MECHANISM-TASK.png`` per task
    (:func:`.figures.task_figure`) and ``MECHANISM-bandwidth.png`` per mechanism with a sine
    task (:func:`.figures.bandwidth_figure`); by default of every task a bench can run."""
    from .figures import bandwidth_figure_name, task_figure_name

    names = {f"{task_figure_name(t)}.png" for t in tasks}
    names |= {f"{bandwidth_figure_name(t.mechanism)}.png" for t in tasks if t.kind == "sine"}
    return frozenset(names)


def own_files() -> OwnFiles:
    """What a bench writes into its ``--out``, by exact names (:mod:`smafinger.outdir`): the
    tables, and in ``figures/`` the figure of every task any bench can run
    (:data:`~.tasks.ALL_TASKS`), so that a second bench removes the figures of tasks it did not run."""
    return OwnFiles("bench-controllers", "a bench", frozenset(TABLE_FILES), {FIGURES_DIR: figure_names()})


def write_report(res: BenchResult, tasks: Sequence[Task], out: Path, figures: bool = True, pool=None,
                 on_progress: Callable[[int, int], None] | None = None) -> list[Path]:
    """Write controllers.csv, bandwidth.csv, controllers.md, goals.json and the figures into ``out``
    (the figures drawn on ``pool`` if given, ``on_progress(done, total)`` after each:
    :func:`.figures.task_figures`); returns the files' paths.

    All or nothing (:func:`smafinger.outdir.staged`): the files are written into a hidden folder
    inside ``out`` and then replace whatever an earlier bench wrote there (:func:`own_files`;
    ``figures/`` too, so ``figures=False`` leaves none). ``out`` may be new (its parent a
    folder) or a folder holding only a bench's files; else
    :class:`~smafinger.files.OutputError` (:func:`smafinger.outdir.check_out_dir`, which the
    command line calls before the runs)."""
    out = Path(out)
    text = markdown(res, tasks)
    g = goals(res.rows)
    plots = []
    if figures:
        from .figures import task_figures

        plots = task_figures(res, tasks, pool, on_progress)  # (name, PNG bytes), drawn before anything is written
    own = own_files()
    odd = [name for name, _ in plots if f"{name}.png" not in own.folders[FIGURES_DIR]]
    if odd:  # figures.py names a figure figure_names does not: a second bench could not remove it
        raise RuntimeError(f"figure {odd[0]!r} is not among the bench's own file names (bench/report.py figure_names)")
    check_out_dir(out, own)  # before the folder is made: a bad --out leaves nothing
    with staged(out, own) as stage:
        for name, frame in (("controllers.csv", res.rows), ("bandwidth.csv", res.bandwidth)):
            frame.to_csv(stage / name, index=False)
        (stage / "controllers.md").write_text(text + "\n", encoding="utf-8")
        (stage / "goals.json").write_text(json.dumps(g, indent=2) + "\n", encoding="utf-8")
        if plots:
            (stage / FIGURES_DIR).mkdir()
            for name, data in plots:
                (stage / FIGURES_DIR / f"{name}.png").write_bytes(data)
    return [out / name for name in TABLE_FILES] + [out / FIGURES_DIR / f"{name}.png" for name, _ in plots]
