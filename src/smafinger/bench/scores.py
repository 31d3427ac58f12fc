"""The bench's metrics of one run, each defined once here (building blocks from
:mod:`smafinger.metrics`), in the mechanism's user unit (deg for the joint, mm for a slider).

- ``rms_error``: RMS of q - q_F over the run (sine tasks: after the transient);
- ``time_to_target_s``: mean over segments of the time to enter the target for good (within
  the run's tolerance for its hold time; the engine's rule); ``cycle_s``: their sum, the full
  cycle time of Fig. 15 (every target issued on reach);
- ``unreached``: segments whose target was never reached, issued or not;
- ``overshoot``: the largest overshoot past a segment's target in the direction of its move;
- ``settling_s``: the longest time for a segment to stay within :data:`SETTLE_BAND` of its target;
- ``limit_cycle``: the largest peak-to-peak of q over the last :data:`~.tasks.HOLD_WINDOW_S`
  of a hold (a segment that lasts that long after its target is reached, or never reaches it;
  not a target left on reach), the amplitude of any limit cycle at rest;
- ``hold_error``: the largest |mean q - q_F| over those windows (the static error of a hold);
- ``energy_J``: the electrical energy delivered, all wires; ``peak_T_C``: the hottest wire;
  ``interlock_violations``: sub-steps with opposing wires driven at once (Sec. 2.6);
- sine tasks: ``gain`` (fitted amplitude of q over that of q_F) and ``phase_deg`` (of q
  relative to q_F), from a least-squares sinusoid fit at the task's frequency.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..metrics import motion_direction, overshoot_deg, settle_time, window
from .tasks import HOLD_WINDOW_S, Task

#: settling band, user units
SETTLE_BAND = {"deg": 0.5, "m": 0.2e-3}
#: user unit -> the unit the bench reports (the slider's metres as millimetres)
REPORT_SCALE = {"deg": (1.0, "deg"), "m": (1e3, "mm")}
#: a gain at or below this is a run that did not move: no log-log interpolation to it (:func:`bandwidth`)
GAIN_FLOOR = 1e-6


def sine_fit(t: np.ndarray, x: np.ndarray, frequency_hz: float) -> tuple[float, float, float]:
    """(amplitude, phase [rad], offset) of the least-squares fit x ~ a sin(w t + phi) + c."""
    w = 2.0 * math.pi * frequency_hz
    A = np.column_stack([np.sin(w * t), np.cos(w * t), np.ones_like(t)])
    (s, c, off), *_ = np.linalg.lstsq(A, x, rcond=None)
    return float(math.hypot(s, c)), float(math.atan2(c, s)), float(off)


@dataclass(frozen=True)
class RunRecord:
    """What the bench keeps of a run (made in the worker by :func:`record_of`): the coordinate and
    its target in the user unit, per-wire temperature, duty and resistance (float32 except
    time), each segment's (start, end, target, reached_s), the energy and interlock count."""

    unit: str
    wires: tuple[str, ...]
    t: np.ndarray
    q: np.ndarray
    q_ref: np.ndarray
    T_C: dict
    duty: dict
    R_ohm: dict
    segments: tuple
    energy_J: float
    violations: int
    n_segments: int  #: the profile's segments (those that never started are not in ``segments``)


def record_of(result) -> RunRecord:
    """A :class:`RunRecord` of a :class:`~smafinger.results.SimulationResult` (the batch ``reduce``)."""
    p = result.spec.params
    unit = p.coordinate.unit
    segs = []
    starts = [(i, s) for i, s in enumerate(result.segment_start_s) if s >= 0]
    for j, (i, s) in enumerate(starts):
        end = starts[j + 1][1] if j + 1 < len(starts) else result.spec.t_end_s
        reached = result.segment_reached_s[i]
        segs.append((float(s), float(end), result.spec.profile.segments[i].target,
                     None if math.isnan(reached) else float(reached)))

    def f32(name: str) -> np.ndarray:
        return np.asarray(result.signal(name), dtype=np.float32)

    return RunRecord(
        unit, tuple(p.wire_names), np.asarray(result.t, dtype=np.float64),
        np.asarray(result.signal(f"{p.coordinate.name}_{unit}"), dtype=np.float64),
        np.asarray(result.signal(f"{p.coordinate.name}_ref_{unit}"), dtype=np.float64),
        {w: f32(f"T_{w}_C") for w in p.wire_names}, {w: f32(f"duty_{w}") for w in p.wire_names},
        {w: f32(f"R_{w}_ohm") for w in p.wire_names}, tuple(segs),
        float(sum(result.signal(f"electrical_energy_{w}_J")[-1] for w in p.wire_names)),
        int(result.interlock_violations), len(result.spec.profile.segments))


def task_scores(task: Task, rec: RunRecord) -> dict:
    """The bench metrics of a run of ``task``, JSON-ready (``None``: undefined)."""
    scale, shown = REPORT_SCALE[rec.unit]
    t, q, q_ref = rec.t, rec.q, rec.q_ref
    out: dict = {"unit": shown}
    if task.kind == "sine":
        m = t >= task.fit_start_s
        out["rms_error"] = float(np.sqrt(np.mean((q[m] - q_ref[m]) ** 2))) * scale
        a_ref, ph_ref, _ = sine_fit(t[m], q_ref[m], task.frequency_hz)
        a, ph, _ = sine_fit(t[m], q[m], task.frequency_hz)
        out["gain"] = a / a_ref
        out["phase_deg"] = math.degrees(math.remainder(ph - ph_ref, 2.0 * math.pi))
    else:
        out["rms_error"] = float(np.sqrt(np.mean((q - q_ref) ** 2))) * scale
        out.update(_segment_scores(t, q, rec.segments, rec.n_segments, rec.unit, scale))
        if task.kind != "cycle":
            del out["cycle_s"]
    out["energy_J"] = rec.energy_J
    out["peak_T_C"] = float(max(np.max(T) for T in rec.T_C.values()))
    out["interlock_violations"] = rec.violations
    return out


def _segment_scores(t, q, segments, n_segments: int, unit: str, scale: float) -> dict:
    """Scores of the segments that started; a target never issued (the run ended first, or a
    target before it was never reached) counts as unreached, and leaves the cycle unfinished."""
    reached = [r for *_, r in segments if r is not None]
    overshoot, settle, cycle, error = 0.0, 0.0, None, None
    q_prev = float(q[0])
    for start, end, target, r in segments:
        overshoot = max(overshoot, overshoot_deg(q[window(t, start, end)], target, motion_direction(q_prev, target)))
        s = settle_time(t, q, target, start, end, SETTLE_BAND[unit])
        settle = math.inf if s is None else max(settle, s)
        if r is None or end - (start + r) >= HOLD_WINDOW_S:  # a hold (not a target left on reach)
            hold = q[window(t, end - HOLD_WINDOW_S, end)]
            cycle = max(cycle or 0.0, float(np.ptp(hold)))
            error = max(error or 0.0, abs(float(np.mean(hold)) - target))
        q_prev = target
    return {
        "time_to_target_s": float(np.mean(reached)) if reached else None,
        "cycle_s": float(sum(reached)) if len(reached) == n_segments else None,
        "unreached": n_segments - len(reached),
        "overshoot": overshoot * scale,
        "settling_s": None if math.isinf(settle) else settle,
        "limit_cycle": None if cycle is None else cycle * scale,
        "hold_error": None if error is None else error * scale,
    }


@dataclass(frozen=True)
class Bandwidth:
    """A -3 dB bandwidth as the sine tasks bound it: ``hz`` with ``bound`` ``"="`` (interpolated),
    ``"<="`` (at most the lowest frequency tried, ``hz``), ``">"`` (above the highest, ``hz``
    None) or ``"between"`` (somewhere in (``low_hz``, ``high_hz``), ``hz`` None: the run at
    ``high_hz`` did not move, so no interpolation says where)."""

    hz: float | None
    bound: str
    low_hz: float | None = None
    high_hz: float | None = None


def bandwidth(frequencies: list[float], gains: list[float]) -> Bandwidth:
    """The -3 dB bandwidth: above the highest frequency whose gain is at least 1/sqrt(2), where
    the gain falls below it for good, interpolated in log-log between that sine task and the
    next (a dip at a lower frequency, e.g. from stick-slip at a slow sine, does not count).
    Above the highest frequency tried if none falls below; at most the lowest if none reaches
    the level. When the next task's gain is at or below :data:`GAIN_FLOOR` (a run that did not
    move at all), only the bracket is known: interpolating to the floor gave a value the floor
    set (0.204 Hz between 0.2 and 0.5 Hz whatever the controller)."""
    pts = sorted((f, float(g)) for f, g in zip(frequencies, gains) if g is not None and math.isfinite(g))
    if not pts:
        return Bandwidth(None, ">")
    level = 1.0 / math.sqrt(2.0)
    above = [k for k, (_, g) in enumerate(pts) if g >= level]
    if not above:
        return Bandwidth(pts[0][0], "<=")
    k = above[-1]
    if k == len(pts) - 1:
        return Bandwidth(None, ">", high_hz=pts[-1][0])
    (f0, g0), (f1, g1) = pts[k], pts[k + 1]
    if g1 <= GAIN_FLOOR:
        return Bandwidth(None, "between", f0, f1)
    x = (math.log(level) - math.log(g0)) / (math.log(g1) - math.log(g0))
    return Bandwidth(float(math.exp(math.log(f0) + x * (math.log(f1) - math.log(f0)))), "=", f0, f1)

