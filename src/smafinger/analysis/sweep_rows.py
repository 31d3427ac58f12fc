"""Worker side of a sweep: check a block of points, run a chunk of them, one row per run.

Both functions take the sweep's :class:`~smafinger.analysis.sweep_spec.SweepTemplate` and
the varied values of their points as columns, build each run's spec there (validation
happens in the workers, in parallel) and send back only small things: run ids, or the
table rows and the decimated float32 traces.

The columns follow each mechanism's coordinate and wire names (``theta_max_deg`` and
``heat_upper_J`` for the finger joint, ``position_max_m`` and ``heat_wire_J`` for the linear
actuator). One table schema serves every sweep: it lists the columns of every mechanism of
:data:`~smafinger.parameters.MECHANISMS`, and a run fills those of its own mechanism (the
others stay empty). Energy is named for what it is (:mod:`smafinger.metrics`):
``electrical_energy_{wire}_J`` at the wire's terminals, ``heat_{wire}_J`` what the model's
Eq. (11) puts into the wire.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..engine.batch import FLOAT64_SIGNALS, warm_up
from ..engine.run import run_spec
from ..engine.signals import COORDINATE_NAMES
from ..parameters import MECHANISMS
from ..plausibility import hinted
from ..step_check import half_step, with_step_check
from .sweep_spec import SPEC_ERRORS, SweepTemplate, run_id

#: the joint has started to move once it is this far from its initial angle
MOTION_THRESHOLD_DEG = 0.5
#: the slider has started to move once it is this far from its start position [m]
MOTION_THRESHOLD_M = 0.1e-3
#: the motion threshold in each coordinate unit
MOTION_THRESHOLDS = {"deg": MOTION_THRESHOLD_DEG, "m": MOTION_THRESHOLD_M}
#: per-wire metric columns, ``{wire}`` replaced by each wire's name
WIRE_METRICS = ("electrical_energy_{wire}_J", "heat_{wire}_J", "peak_T_{wire}_C", "peak_stress_{wire}_Pa")
#: per-coordinate metric columns, ``{q}`` replaced by the coordinate's name, ``{unit}`` by its unit
COORDINATE_METRICS = ("{q}_max_{unit}", "{q}_min_{unit}", "{q}_final_{unit}")
#: per-wire trace columns
WIRE_TRACES = ("T_{wire}_C", "xi_{wire}", "sigma_{wire}_Pa", "V_{wire}_V", "duty_{wire}")


def _unique(items) -> tuple:
    return tuple(dict.fromkeys(items))


#: every mechanism's wire names and coordinates (name, unit), in registry order
WIRE_NAMES = _unique(w for cls in MECHANISMS.values() for w in cls.wire_names)
COORDINATES = _unique((cls.coordinate.name, cls.coordinate.unit) for cls in MECHANISMS.values())
UNITS = _unique(unit for _, unit in COORDINATES)
#: with [sweep] check_step: the coordinate's error estimated from the same run at half the step
#: (smafinger.step_check: twice the difference), RMS and largest, in each unit; NaN without
STEP_COLUMNS = tuple(f"step_error_{stat}_{u}" for u in UNITS for stat in ("rms", "max"))
#: with [sweep] check_step: the ratio of the two runs' sub-step counts (below the check's
#: MIN_REFINEMENT it does not judge, and the errors are NaN); NaN where the run was not checked
STEP_REFINEMENT = "step_refinement"
#: what a sweep's failed step check advises (its row's error)
SWEEP_CHECK_REMEDY = "remove check_step from [sweep] to skip the check"
#: per-run metric columns, in table order (then the per-segment ``seg{i}_*`` columns)
METRIC_COLUMNS = (
    "status", "error",
    *(c.format(wire=w) for w in WIRE_NAMES for c in WIRE_METRICS),
    "interlock_violations",
    *(c.format(q=q, unit=u) for q, u in COORDINATES for c in COORDINATE_METRICS),
    "motion_start_s", "steps", "wall_s",
    # the numerics the run used (engine.numerics: a point's varied values can change its default)
    "run_method", "run_dt_s", "run_pwm",
    # the run's warnings (its metrics': physically absurd results, smafinger.plausibility; a target never
    # pursued; with [sweep] check_step, a step the run has not converged at), "; "-joined
    "warnings",
    *STEP_COLUMNS, STEP_REFINEMENT,
)
INT_COLUMNS = ("interlock_violations", "steps")
#: text columns (the others are numbers)
STRING_COLUMNS = ("run_id", "status", "error", "run_method", "run_pwm", "warnings")
#: joins a run's warnings in its ``warnings`` column ("" when it has none)
WARNINGS_SEPARATOR = "; "
#: per-segment columns: target, start, reach time and overshoot (target and overshoot in every unit)
SEGMENT_COLUMNS = (f"target_{UNITS[0]}", "start_s", "reached_s", f"overshoot_{UNITS[0]}",
                   *(f"{c}_{u}" for u in UNITS[1:] for c in ("target", "overshoot")))
TRACE_COLUMNS = ("t_s", *_unique(COORDINATE_NAMES[m][k] for m in MECHANISMS for k in ("q", "q_ref", "v")),
                 *(c.format(wire=w) for c in WIRE_TRACES for w in WIRE_NAMES))


def metrics_row(result, traces_interval_s: float | None = None) -> dict:
    """The table row (metrics) of one run; with ``traces_interval_s`` also its sampled trace
    (float32 but time; NaN for the columns of other mechanisms) under the key ``"_trace"``.
    Runs in the worker (picklable, module level)."""
    s = result.summary()
    p = result.spec.params
    q, unit = p.coordinate.name, p.coordinate.unit
    x = np.asarray(result.signal(f"{q}_{unit}"))
    t = np.asarray(result.signal("t_s"))
    moved = np.flatnonzero(np.abs(x - x[0]) > MOTION_THRESHOLDS[unit])
    per_wire = {"electrical_energy_{wire}_J": s["electrical_energy_J"], "heat_{wire}_J": s["heat_J"],
                "peak_T_{wire}_C": s["peak_temperature_C"], "peak_stress_{wire}_Pa": s["peak_stress_Pa"]}
    row = {"status": "ok", "error": ""}
    row.update({c.format(wire=w): float(v[w]) for c, v in per_wire.items() for w in p.wire_names})
    row.update({
        "interlock_violations": int(s["interlock_violations"]),
        f"{q}_max_{unit}": float(np.max(x)), f"{q}_min_{unit}": float(np.min(x)), f"{q}_final_{unit}": float(x[-1]),
        "motion_start_s": float(t[moved[0]]) if moved.size else math.nan,
        "steps": int(s["steps"]), "wall_s": float(s["wall_s"]),
        "run_method": result.spec.method, "run_dt_s": float(result.spec.dt_s), "run_pwm": result.spec.pwm,
        "warnings": WARNINGS_SEPARATOR.join(s["warnings"]),
        **dict.fromkeys((*STEP_COLUMNS, STEP_REFINEMENT), math.nan),
    })
    chk = result.step_check
    if chk is not None:
        row[f"step_error_rms_{unit}"], row[f"step_error_max_{unit}"] = chk.estimated_rms, chk.estimated_max
        row[STEP_REFINEMENT] = chk.refinement
    segs = {seg["index"]: seg for seg in s["segments"]}
    for i, seg_def in enumerate(result.spec.profile.segments):
        seg = segs.get(i)
        row[f"seg{i}_target_{unit}"] = float(seg_def.target)
        row[f"seg{i}_start_s"] = float(seg["start_s"]) if seg else math.nan
        reached = seg["reached_s"] if seg else None
        row[f"seg{i}_reached_s"] = math.nan if reached is None else float(reached)
        over = seg[f"overshoot_{unit}"] if seg else None  # None: a segment with no output sample
        row[f"seg{i}_overshoot_{unit}"] = math.nan if over is None else float(over)
    if traces_interval_s:
        row["_trace"] = trace(result, trace_step(traces_interval_s, result.spec.output_interval_s))
    return row


def trace(result, every: int) -> dict[str, np.ndarray]:
    """Every :data:`TRACE_COLUMNS` signal of a run, every ``every``-th sample, float32 but
    time; the columns the run's mechanism does not have are NaN."""
    have = set(result.column_names)
    n = len(result.t[::every])
    out = {}
    for c in TRACE_COLUMNS:
        dtype = np.float64 if c in FLOAT64_SIGNALS else np.float32
        out[c] = (np.ascontiguousarray(np.asarray(result.signal(c))[::every], dtype=dtype) if c in have
                  else np.full(n, np.nan, dtype=dtype))
    return out


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
    segments of its runs, and the first bad point."""

    start: int
    ids: np.ndarray
    n_segments: int
    error: tuple[int, dict, str] | None = None


def check_block(template: SweepTemplate, start: int, columns: dict[str, list],
                traces_interval_s: float | None = None, check_step: bool = False) -> CheckedBlock:
    """Build and validate the spec of every point of a block, and compute its run id; with
    ``traces_interval_s``, check that each run can be traced at it (:func:`trace_step`); with
    ``check_step``, that its step has a shorter one (:func:`smafinger.step_check.half_step`).

    Stops at the first bad point: ``error = (point, values, message)``.
    """
    n = len(next(iter(columns.values()))) if columns else 0
    ids = np.zeros(n, dtype="S16")
    n_seg = 0
    for k in range(n):
        values = _values_at(columns, k)
        try:
            spec = template.build(values)
            if traces_interval_s:
                trace_step(traces_interval_s, spec.output_interval_s)
            if check_step:
                half_step(spec)
        except SPEC_ERRORS as exc:
            return CheckedBlock(start, ids[:k], n_seg, (start + k, values, str(exc)))
        ids[k] = run_id(spec).encode()
        n_seg = max(n_seg, len(spec.profile.segments))
    return CheckedBlock(start, ids, n_seg)


def trace_step(traces_interval_s: float, output_interval_s: float) -> int:
    """Every how many output samples a run's trace keeps one. ``traces_interval_s`` must be a
    whole multiple of the run's ``output_interval_s``, so that the traces are sampled at the
    interval their file states (ValueError otherwise)."""
    step = round(traces_interval_s / output_interval_s)
    if step < 1 or abs(step * output_interval_s - traces_interval_s) > 1e-9 * traces_interval_s:
        raise ValueError(f"[sweep] traces_interval_s = {traces_interval_s:g} s is not a whole multiple of the run's "
                         f"output_interval_s = {output_interval_s:g} s")
    return step


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
              traces_interval_s: float | None = None, row=metrics_row, check_step: bool = False) -> RowBlock:
    """Run a chunk of points here, one row each (a failed run is a row with its error).

    ``ids`` are the run ids found by :func:`check_block`; each run's id is computed again
    from the spec that actually ran, and a difference fails the run rather than mislabel
    it. ``row`` makes a run's row (:func:`metrics_row`) from its metrics' signals: without
    traces a run records only those (``run_spec(record="metrics")``; the same row).
    ``check_step``: each run also at half its step (:func:`smafinger.step_check.with_step_check`;
    a failure of that run fails the run's row).
    """
    warm_up()
    rows, traces, failed = [], [], 0
    for k, (point, rid) in enumerate(zip(points, ids)):
        try:
            spec = template.build(_values_at(columns, k))
            if run_id(spec) != rid:
                raise RuntimeError(f"internal error: point {point} was checked as run {rid} but builds "
                                   f"run {run_id(spec)}")
            record = "all" if traces_interval_s else "metrics"
            result = hinted(spec, lambda: run_spec(spec, record=record), style="toml")
            r = row(with_step_check(result, remedy=SWEEP_CHECK_REMEDY) if check_step else result, traces_interval_s)
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
