"""Worker side of a sweep: check a block of points, run a chunk of them, one row per run.

Both functions take the sweep's :class:`~smafinger.analysis.sweep_spec.SweepTemplate` and
the varied values of their points as columns, build each run's spec there (validation
happens in the workers, in parallel) and send back only small things: run ids, or the
table rows and the decimated float32 traces.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..engine.batch import compact_signals, warm_up
from ..engine.run import run_spec
from .sweep_spec import SPEC_ERRORS, SweepTemplate, run_id

#: the joint has started to move once it is this far from its initial angle
MOTION_THRESHOLD_DEG = 0.5
#: per-run metric columns, in table order (then the per-segment ``seg{i}_*`` columns)
METRIC_COLUMNS = (
    "status", "error", "energy_upper_J", "energy_lower_J", "peak_T_upper_C", "peak_T_lower_C",
    "peak_stress_upper_Pa", "peak_stress_lower_Pa", "interlock_violations", "theta_max_deg",
    "theta_min_deg", "theta_final_deg", "motion_start_s", "steps", "wall_s",
)
INT_COLUMNS = ("interlock_violations", "steps")
SEGMENT_COLUMNS = ("target_deg", "start_s", "reached_s", "overshoot_deg")
TRACE_COLUMNS = ("t_s", "theta_deg", "theta_ref_deg", "omega_deg_s", "T_upper_C", "T_lower_C",
                 "xi_upper", "xi_lower", "sigma_upper_Pa", "sigma_lower_Pa", "V_upper_V",
                 "V_lower_V", "duty_upper", "duty_lower")


def metrics_row(result, traces_interval_s: float | None = None) -> dict:
    """The table row (metrics) of one run; with ``traces_interval_s`` also its sampled trace
    (float32 but time, :func:`~smafinger.engine.batch.compact_signals`) under the key
    ``"_trace"``. Runs in the worker (picklable, module level)."""
    s = result.summary()
    th = np.asarray(result.signal("theta_deg"))
    t = np.asarray(result.signal("t_s"))
    moved = np.flatnonzero(np.abs(th - th[0]) > MOTION_THRESHOLD_DEG)
    row = {
        "status": "ok", "error": "",
        "energy_upper_J": s["energy_J"]["upper"], "energy_lower_J": s["energy_J"]["lower"],
        "peak_T_upper_C": s["peak_temperature_C"]["upper"],
        "peak_T_lower_C": s["peak_temperature_C"]["lower"],
        "peak_stress_upper_Pa": s["peak_stress_Pa"]["upper"],
        "peak_stress_lower_Pa": s["peak_stress_Pa"]["lower"],
        "interlock_violations": int(s["interlock_violations"]),
        "theta_max_deg": float(np.max(th)), "theta_min_deg": float(np.min(th)),
        "theta_final_deg": float(th[-1]),
        "motion_start_s": float(t[moved[0]]) if moved.size else math.nan,
        "steps": int(s["steps"]), "wall_s": float(s["wall_s"]),
    }
    segs = {seg["index"]: seg for seg in s["segments"]}
    for i, seg_def in enumerate(result.spec.profile.segments):
        seg = segs.get(i)
        row[f"seg{i}_target_deg"] = float(seg_def.target_deg)
        row[f"seg{i}_start_s"] = float(seg["start_s"]) if seg else math.nan
        reached = seg["reached_s"] if seg else None
        row[f"seg{i}_reached_s"] = math.nan if reached is None else float(reached)
        row[f"seg{i}_overshoot_deg"] = float(seg["overshoot_deg"]) if seg else math.nan
    if traces_interval_s:
        step = max(1, round(traces_interval_s / result.spec.output_interval_s))
        row["_trace"] = compact_signals(result, TRACE_COLUMNS, step)
    return row


def error_row(exc: BaseException) -> dict:
    return {"status": "error", "error": f"{type(exc).__name__}: {exc}"}


def column_order(varied: list[str], n_segments: int) -> list[str]:
    cols = ["run_id", "point", *varied, *METRIC_COLUMNS]
    for i in range(n_segments):
        cols += [f"seg{i}_{c}" for c in SEGMENT_COLUMNS]
    return cols


def _values_at(columns: dict[str, list], k: int) -> dict:
    return {name: col[k] for name, col in columns.items()}


# ---------------------------------------------------------------------------------------
# the check pass
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CheckedBlock:
    """What checking a block of points found: each run's id (bytes, ``S16``), the most
    segments and the longest output interval of its runs, and the first bad point."""

    start: int
    ids: np.ndarray
    n_segments: int
    max_output_interval_s: float
    error: tuple[int, dict, str] | None = None


def check_block(template: SweepTemplate, start: int, columns: dict[str, list]) -> CheckedBlock:
    """Build and validate the spec of every point of a block, and compute its run id.

    Stops at the first bad point: ``error = (point, values, message)``.
    """
    n = len(next(iter(columns.values()))) if columns else 0
    ids = np.zeros(n, dtype="S16")
    n_seg, out_s = 0, 0.0
    for k in range(n):
        values = _values_at(columns, k)
        try:
            spec = template.build(values)
        except SPEC_ERRORS as exc:
            return CheckedBlock(start, ids[:k], n_seg, out_s, (start + k, values, str(exc)))
        if spec.params.mechanism != "joint":  # the table's columns are the joint's (metrics_row)
            msg = (f"params {spec.params.name!r} is a {spec.params.mechanism} set; sweeps tabulate the finger "
                   "joint only (the angle, the upper and the lower wire)")
            return CheckedBlock(start, ids[:k], n_seg, out_s, (start + k, values, msg))
        ids[k] = run_id(spec).encode()
        n_seg = max(n_seg, len(spec.profile.segments))
        out_s = max(out_s, spec.output_interval_s)
    return CheckedBlock(start, ids, n_seg, out_s)


# ---------------------------------------------------------------------------------------
# the run pass
# ---------------------------------------------------------------------------------------
@dataclass
class RowBlock:
    """The rows of a chunk of runs (dicts with ``run_id`` and ``point``) and, with traces,
    their samples as columns (``run_id``, ``point``, then :data:`TRACE_COLUMNS`)."""

    rows: list[dict]
    traces: dict | None
    failed: int


def run_block(template: SweepTemplate, points: list[int], ids: list[str], columns: dict[str, list],
              traces_interval_s: float | None = None, row=metrics_row) -> RowBlock:
    """Run a chunk of points here, one row each (a failed run is a row with its error).

    ``ids`` are the run ids found by :func:`check_block`; each run's id is computed again
    from the spec that actually ran, and a difference fails the run rather than mislabel
    it. ``row`` makes a run's row (:func:`metrics_row`).
    """
    warm_up()
    rows, traces, failed = [], [], 0
    for k, (point, rid) in enumerate(zip(points, ids)):
        try:
            spec = template.build(_values_at(columns, k))
            if run_id(spec) != rid:
                raise RuntimeError(f"internal error: point {point} was checked as run {rid} but builds "
                                   f"run {run_id(spec)}")
            r = row(run_spec(spec), traces_interval_s)
        except Exception as exc:  # noqa: BLE001 - reported per run, the sweep goes on
            r = error_row(exc)
            failed += 1
        tr = r.pop("_trace", None)
        if tr is not None:
            traces.append((rid, point, tr))
        rows.append({"run_id": rid, "point": int(point), **r})
    return RowBlock(rows, _trace_columns(traces) if traces_interval_s else None, failed)


def _trace_columns(traces: list[tuple[str, int, dict]]) -> dict:
    lengths = [len(tr["t_s"]) for _, _, tr in traces]
    cols = {"run_id": np.repeat(np.array([rid for rid, _, _ in traces], dtype=object), lengths),
            "point": np.repeat(np.array([p for _, p, _ in traces], dtype=np.int64), lengths)}
    for c in TRACE_COLUMNS:
        parts = [tr[c] for _, _, tr in traces]
        cols[c] = np.concatenate(parts) if parts else np.zeros(0, np.float64 if c == "t_s" else np.float32)
    return cols
