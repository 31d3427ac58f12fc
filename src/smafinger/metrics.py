"""Every metric of a run, defined once: times in s, angles in deg, on sampled signals.

The functions take plain arrays (a run's output or measured data), so the same definition
serves :func:`smafinger.results.compute_metrics`, the paper layer
(:mod:`smafinger.paper`) and the sweeps. Each threshold is a named constant below and an
argument of the function that uses it. The cycle times of Fig. 15 are in
:mod:`smafinger.cycle_metrics` (imported here too).

Conventions
-----------
- A sample belongs to a time window ``[start, end]`` if it lies within :data:`EDGE_S`
  (half a tick of the engine's 1 ns clock) of it: run times are whole ticks.
- Overshoot is measured in the direction of the motion: from where the joint was when the
  move started, towards the target and beyond it (:func:`overshoot_deg`).
- ``None`` means "never" (a time that did not happen in the run).
- Energy is named for what it is: ``electrical_energy_J`` is the energy at a wire's terminals
  (V^2 / (R_w L_w) integrated, what a supply delivers), ``heat_J`` the heat the model's Eq. (11)
  puts into the wire. With the paper's per-metre reading of Eq. (11) (``joule_heating =
  per-metre``) the two differ by the factor 1 / L_w^2 (6.75 for the paper's 0.385 m wire).
  ``energy_J`` is smafinger 0.1's name of the electrical energy, kept for compatibility.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from .cycle_metrics import cycle_time, elapsed_time, reached_sum, reduction  # noqa: F401 (re-exported)
from .engine.clock import TICK_S

#: a sample belongs to a window if within this of its edges (half a clock tick) [s]
EDGE_S = 0.5 * TICK_S
#: the joint has started to move once this far from its reference angle [deg]
START_OF_MOTION_DEG = 0.1
#: "rise" and "return" times: the first time this fraction of the way is covered
WAY_FRACTION = 0.9
#: open loop: "still moving" is the mean speed over this last part of the heating [s]
STILL_WINDOW_S = 1.0
#: settling time: the joint stays within this band of the target [deg]
SETTLE_BAND_DEG = 0.1
#: a wire is back to martensite once its martensite fraction reaches this
MARTENSITE_XI = 0.999
#: cooling phase: the fall back past the target after it is looked for within this time [s]
COOLING_WINDOW_S = 5.0
#: the joint is at rest once slower than this [deg/s]
REST_SPEED_DEG_S = 0.05
#: angle comparisons with a tolerance allow this much rounding [deg]
ANGLE_EPS_DEG = 1e-12


# ---------------------------------------------------------------------------------------
# building blocks
# ---------------------------------------------------------------------------------------
def window(t: np.ndarray, start_s: float = -math.inf, end_s: float = math.inf) -> np.ndarray:
    """Mask of the samples in ``[start_s, end_s]`` (edges within :data:`EDGE_S`)."""
    return (t >= start_s - EDGE_S) & (t <= end_s + EDGE_S)


def window_slice(t: np.ndarray, start_s: float = -math.inf, end_s: float = math.inf) -> slice:
    """:func:`window` as a slice, for ascending ``t`` (found by bisection, without a pass over
    the samples): ``t[window_slice(t, a, b)]`` is ``t[window(t, a, b)]``."""
    return slice(int(np.searchsorted(t, start_s - EDGE_S, side="left")),
                 int(np.searchsorted(t, end_s + EDGE_S, side="right")))


def first_time(mask: np.ndarray, t: np.ndarray) -> float | None:
    """Time of the first sample where ``mask`` is true; ``None`` if there is none."""
    idx = np.flatnonzero(mask)
    return float(t[idx[0]]) if idx.size else None


def motion_direction(from_deg: float, target_deg: float) -> float:
    """+1 towards a larger angle, -1 towards a smaller one, 0 if already there."""
    return float(np.sign(target_deg - from_deg))


def overshoot_deg(theta_deg: np.ndarray, target_deg: float, direction: float) -> float:
    """How far the joint went past ``target_deg`` in ``direction`` (>= 0; 0 if it did not).

    The one definition of overshoot: ``max(0, max(direction * (theta - target)))``.
    """
    if direction == 0 or theta_deg.size == 0:
        return 0.0
    return max(0.0, float(np.max(direction * (theta_deg - target_deg))))


def motion_start_s(t: np.ndarray, theta_deg: np.ndarray, threshold_deg: float = START_OF_MOTION_DEG,
                   reference_deg: float | None = None) -> float | None:
    """First time the joint is more than ``threshold_deg`` from ``reference_deg``.

    ``reference_deg`` defaults to the first sample's angle. ``None`` if it never moves.
    """
    if t.size == 0:
        return None
    ref = float(theta_deg[0]) if reference_deg is None else reference_deg
    return first_time(np.abs(theta_deg - ref) > threshold_deg, t)


def _inside_from(ts: np.ndarray, outside: np.ndarray, start_s: float) -> float | None:
    """Time from ``start_s`` after which ``outside`` stays false to the last sample ``ts``
    (0 if never true; ``None`` if true at the last sample, or if there is no sample: an empty
    window had 0, "at once", found by an API fuzz)."""
    if len(ts) == 0:
        return None
    if not outside.any():
        return 0.0
    k = int(np.flatnonzero(outside)[-1])
    if k == len(ts) - 1:
        return None
    return float(ts[k + 1] - start_s)


def settle_time(t: np.ndarray, theta_deg: np.ndarray, target_deg: float, start_s: float,
                end_s: float, band_deg: float = SETTLE_BAND_DEG) -> float | None:
    """Time from ``start_s`` after which ``|theta - target| <= band_deg`` until ``end_s``.

    0 if always inside; ``None`` if the joint is still outside at ``end_s`` (or no sample
    falls between ``start_s`` and ``end_s``).
    """
    m = window(t, start_s, end_s)
    return _inside_from(t[m], np.abs(theta_deg[m] - target_deg) > band_deg, start_s)


def rest_time(t: np.ndarray, speed: np.ndarray, start_s: float, end_s: float,
              threshold: float = REST_SPEED_DEG_S) -> float | None:
    """Time from ``start_s`` after which ``|speed| <= threshold`` until ``end_s`` (the joint at rest).

    0 if it never moves faster; ``None`` if it is still moving at ``end_s`` (or no sample
    falls between ``start_s`` and ``end_s``).
    """
    m = window(t, start_s, end_s)
    return _inside_from(t[m], np.abs(speed[m]) > threshold, start_s)


def time_to_reach(t: np.ndarray, theta_deg: np.ndarray, target_deg: float, start_s: float,
                  end_s: float, tol_deg: float, hold_s: float) -> float | None:
    """First time (from ``start_s``) after which theta stays within ``tol_deg`` for ``hold_s``.

    The engine's "reached" rule applied to sampled signals (e.g. measured data); the
    engine itself records it at every step. ``None`` if it never happens in the window.
    """
    m = window(t, start_s, end_s)
    ts = t[m]
    inside = np.abs(theta_deg[m] - target_deg) <= tol_deg + ANGLE_EPS_DEG
    if not inside.any():
        return None
    idx = np.flatnonzero(inside)
    breaks = np.flatnonzero(np.diff(idx) > 1)
    run_first = np.concatenate(([idx[0]], idx[breaks + 1]))
    run_last = np.concatenate((idx[breaks], [idx[-1]]))
    for f, last in zip(run_first, run_last):
        if ts[last] - ts[f] >= hold_s - EDGE_S:
            return float(ts[f] - start_s)
    return None


def martensite_time(t: np.ndarray, xi: np.ndarray, start_s: float,
                    full_xi: float = MARTENSITE_XI) -> float | None:
    """Time from ``start_s`` until the wire is back to martensite (``xi >= full_xi``).

    ``None`` if it already was at ``start_s`` (no cooling to wait for) or never gets there.
    """
    m = window(t, start_s)
    was = float(xi[m][0]) if m.any() else 1.0
    hit = first_time(m & (xi >= full_xi), t)
    return None if was >= full_xi or hit is None else hit - start_s


def cooled_time(t: np.ndarray, xi: Mapping[str, np.ndarray], start_s: float, end_s: float,
                full_xi: float = MARTENSITE_XI) -> float | None:
    """Time from ``start_s`` until every wire that was partly austenite then is back to
    martensite (the end of the cooling phases a move waits for, Sec. 4.1).

    ``xi``: each wire's martensite fraction. 0 if every wire was martensite at ``start_s``;
    ``None`` if one is not back by ``end_s``.
    """
    times = []
    for x in xi.values():
        m = window(t, start_s, end_s)
        if not m.any() or float(x[m][0]) >= full_xi:
            continue
        back = martensite_time(t, np.where(m, x, 0.0), start_s, full_xi)
        if back is None:
            return None
        times.append(back)
    return max(times, default=0.0)


def _some(t: np.ndarray) -> None:
    """ValueError for signals with no sample (an IndexError came from inside; found by an API fuzz)."""
    if len(t) == 0:
        raise ValueError("t has no samples: the metrics need at least one")


def sample_at(t: np.ndarray, x: np.ndarray, at_s: float) -> float:
    """``x`` at the first sample at or after ``at_s`` (the last sample if none)."""
    _some(t)
    return float(x[min(int(np.searchsorted(t, at_s - EDGE_S)), len(t) - 1)])


def increase(t: np.ndarray, cumulative: np.ndarray, start_s: float, end_s: float) -> float:
    """Increase of a cumulative signal (e.g. energy) from ``start_s`` to ``end_s``."""
    _some(t)
    k0 = int(np.searchsorted(t, start_s - EDGE_S))
    k1 = min(int(np.searchsorted(t, end_s - EDGE_S)), len(t) - 1)
    return float(cumulative[k1] - cumulative[k0])


# ---------------------------------------------------------------------------------------
# open loop (Sec. 3.1) and the cooling phase (Sec. 2.6, Fig. 11)
# ---------------------------------------------------------------------------------------
def openloop_metrics(t: np.ndarray, theta_deg: np.ndarray, t_off_s: float,
                     move_deg: float = START_OF_MOTION_DEG, fraction: float = WAY_FRACTION,
                     still_window_s: float = STILL_WINDOW_S) -> dict:
    """Range, start and speed of an open-loop run heated until ``t_off_s`` (Sec. 3.1).

    Returns ``range_deg`` (largest ``|theta - theta(0)|`` while heated), ``start_s`` (first
    time it has moved ``move_deg``), ``rise90_s`` (first time it covers ``fraction`` of its
    range), ``still_moving_deg_s`` (mean speed over the last ``still_window_s`` of heating),
    ``angle_at_off_deg``, ``final_deg`` (last sample), and, from ``t_off_s``,
    ``return_start_s`` (moved ``move_deg`` back) and ``return90_s`` (covered ``fraction`` of
    the way from ``angle_at_off_deg`` to ``final_deg``).
    """
    _some(t)
    d = np.abs(theta_deg - float(theta_deg[0]))
    heat = window(t, end_s=t_off_s)
    if not heat.any():
        raise ValueError(f"t_off_s = {t_off_s!r} is before the first sample ({float(t[0]):g} s): nothing was heated")
    cool = ~heat
    rng = float(np.max(d[heat]))
    k_off = int(np.flatnonzero(heat)[-1])
    k_still = int(np.searchsorted(t, t_off_s - still_window_s - EDGE_S))
    span = max(EDGE_S, float(t[k_off] - t[k_still]))
    still = abs(float(theta_deg[k_off] - theta_deg[k_still])) / span
    th_off, th_end = float(theta_deg[k_off]), float(theta_deg[-1])
    way = abs(th_off - th_end)
    moved = rng >= move_deg
    ret_start = motion_start_s(t[cool], theta_deg[cool], move_deg, reference_deg=th_off)
    ret90 = (first_time(cool & (np.abs(theta_deg - th_end) <= (1.0 - fraction) * way), t)
             if way >= move_deg else None)
    return {
        "range_deg": rng,
        "start_s": motion_start_s(t[heat], theta_deg[heat], move_deg) if moved else None,
        "rise90_s": first_time(heat & (d >= fraction * rng), t) if moved else None,
        "still_moving_deg_s": still,
        "angle_at_off_deg": th_off,
        "final_deg": th_end,
        "return_start_s": None if ret_start is None else ret_start - t_off_s,
        "return90_s": None if ret90 is None else ret90 - t_off_s,
    }


def cooling_phase_metrics(t: np.ndarray, theta_deg: np.ndarray, T_agonist_C: np.ndarray,
                          target_deg: float, window_s: float = COOLING_WINDOW_S) -> dict:
    """The agonist's first cooling phase: the joint past ``target_deg`` (Sec. 2.6, Fig. 11).

    The move is from the first sample towards ``target_deg``; "past" is in its direction.
    Returned: ``overshoot_deg``, the move's overshoot (:func:`overshoot_deg`, the one
    definition: how far the joint goes past the target in the direction of the move); the
    first cooling phase's ``cooling_start_s`` and duration ``cooling_s``, the mean fall of the
    agonist's temperature over it ``cooling_rate_C_s``; and ``fall_back_deg``, how far the
    joint then falls back past the target, against the move's direction, within ``window_s``
    after the phase ends. ``None`` values when the joint never passes the target.
    """
    direction = motion_direction(float(theta_deg[0]), target_deg)
    out: dict = {"overshoot_deg": overshoot_deg(theta_deg, target_deg, direction), "cooling_start_s": None,
                 "cooling_s": None, "cooling_rate_C_s": None, "fall_back_deg": None}
    past = direction * (theta_deg - target_deg) > 0
    if direction == 0 or not past.any():
        return out
    i0 = int(np.argmax(past))
    back = np.flatnonzero(~past[i0:])
    i1 = i0 + int(back[0]) if back.size else len(t) - 1
    dur = float(t[i1] - t[i0])
    after = window(t, float(t[i1]), float(t[i1]) + window_s)
    out.update(cooling_start_s=float(t[i0]), cooling_s=dur,
               cooling_rate_C_s=float((T_agonist_C[i0] - T_agonist_C[i1]) / dur) if dur > 0 else None,
               fall_back_deg=(overshoot_deg(theta_deg[after], target_deg, -direction) if back.size else None))
    return out


def onoff_cycle_metrics(t: np.ndarray, theta_deg: np.ndarray, T_wire_C: np.ndarray, T_casing_C: np.ndarray,
                        xi: np.ndarray, on_s: Sequence[tuple[float, float]],
                        fraction: float = WAY_FRACTION) -> list[dict]:
    """Open-loop on/off cycles (Sec. 3.2, Fig. 10a): one dict per ``(on, off)`` interval.

    A cycle runs from its ``on`` time to the next cycle's (the last one to the end of the run).
    Returned per cycle: ``on_s``, ``off_s``, ``end_s``; the casing temperature at the start, at
    the switch-off and at the end of the cool-down (``casing_start_C``, ``casing_off_C``,
    ``casing_end_C``); the wire's peak and end temperatures; ``range_deg`` (largest move from
    the cycle's starting angle while heated); ``cooling_s``, the cooling time of the move: from
    the switch-off until the joint has come back ``fraction`` of the way to the cycle's starting
    angle (``None`` if not within the cool-down); and ``martensite_s``, from the switch-off until
    the wire is back to martensite (``None`` if not within the cool-down).
    """
    out = []
    for k, (on, off) in enumerate(on_s):
        end = on_s[k + 1][0] if k + 1 < len(on_s) else float(t[-1])
        th0, th_off = sample_at(t, theta_deg, on), sample_at(t, theta_deg, off)
        heat, cool = window(t, on, off), window(t, off, end)
        if not heat.any():
            raise ValueError(f"on_s[{k}] = ({on!r}, {off!r}): no sample of the run ({float(t[0]):g} to "
                             f"{float(t[-1]):g} s) falls in it")
        way = abs(th_off - th0)
        back = first_time(cool & (np.abs(theta_deg - th0) <= (1.0 - fraction) * way), t) if way > 0 else None
        mart = martensite_time(t, np.where(cool, xi, 0.0), off)
        out.append({
            "on_s": on, "off_s": off, "end_s": end,
            "casing_start_C": sample_at(t, T_casing_C, on), "casing_off_C": sample_at(t, T_casing_C, off),
            "casing_end_C": sample_at(t, T_casing_C, end),
            "wire_peak_C": float(np.max(T_wire_C[heat])), "wire_end_C": sample_at(t, T_wire_C, end),
            "range_deg": float(np.max(np.abs(theta_deg[heat] - th0))),
            "cooling_s": None if back is None else back - off,
            "martensite_s": mart,
        })
    return out


# ---------------------------------------------------------------------------------------
# per segment and per run (results.compute_metrics)
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Span:
    """One profile segment as it ran: where it started and ended, and its target (in the
    mechanism's unit: deg for the joint, m for a linear actuator)."""

    index: int
    start_s: float
    end_s: float
    target: float
    enable: str
    reached_s: float | None
    #: a target a controller pursued (False: an open-loop run's placeholder, with no overshoot)
    pursued: bool = True


def segment_metrics(t: np.ndarray, q: np.ndarray, span: Span,
                    temperature_C: Mapping[str, np.ndarray], energy_J: Mapping[str, np.ndarray],
                    unit: str = "deg", heat_J: Mapping[str, np.ndarray] | None = None) -> dict:
    """A segment's reach time, overshoot (in the direction of its move), energy and peak
    temperature per wire. ``energy_J`` (cumulative electrical energy at each wire's terminals)
    and ``heat_J`` (cumulative heat the model puts into each wire) are signals; the segment's
    electrical energy is given as ``electrical_energy_J`` (and as ``energy_J``, its 0.1 name),
    its heat as ``heat_J``. ``q`` is the joint angle [deg] or a slider's position [m]; ``unit``
    names the keys (``target_deg``, ``overshoot_m``). Everything but the span's own times is read
    from the samples: with a coarse output interval the energy between the segment's start and the
    next sample is credited to the segment before it."""
    m = window_slice(t, span.start_s, span.end_s)  # t: a run's output times, ascending
    # None: no output sample falls in the segment (it is shorter than the output interval)
    some = m.stop > m.start
    electrical = {w: increase(t, e, span.start_s, span.end_s) if some else None for w, e in energy_J.items()}
    k0 = min(int(np.searchsorted(t, span.start_s - EDGE_S)), len(t) - 1)  # a segment may fall between samples
    direction = motion_direction(float(q[k0]), span.target)
    return {
        "index": span.index,
        "start_s": span.start_s,
        "end_s": span.end_s,
        f"target_{unit}": span.target,
        "enable": span.enable,
        "reached_s": span.reached_s,
        f"overshoot_{unit}": overshoot_deg(q[m], span.target, direction) if some and span.pursued else None,
        "energy_J": electrical,
        "electrical_energy_J": electrical,
        **({"heat_J": {w: increase(t, e, span.start_s, span.end_s) if some else None for w, e in heat_J.items()}}
           if heat_J is not None else {}),
        "peak_temperature_C": {w: float(np.max(T[m])) if some else None for w, T in temperature_C.items()},
    }


def run_metrics(t: np.ndarray, q: np.ndarray, spans: Sequence[Span],
                temperature_C: Mapping[str, np.ndarray], stress_Pa: Mapping[str, np.ndarray],
                energy_J: Mapping[str, np.ndarray], unit: str = "deg",
                heat_J: Mapping[str, np.ndarray] | None = None) -> dict:
    """Per-segment metrics, and each wire's energy (electrical, at its terminals; and the heat the
    model puts into it, if given), peak temperature and peak stress (cumulative energy signals)."""
    _some(t)
    return {
        "segments": [segment_metrics(t, q, s, temperature_C, energy_J, unit, heat_J) for s in spans],
        "energy_J": {w: float(e[-1]) for w, e in energy_J.items()},
        "heat_J": {w: float(e[-1]) for w, e in (heat_J or {}).items()},
        "peak_temperature_C": {w: float(np.max(T)) for w, T in temperature_C.items()},
        "peak_stress_Pa": {w: float(np.max(s)) for w, s in stress_Pa.items()},
    }


__all__ = [
    "EDGE_S", "START_OF_MOTION_DEG", "WAY_FRACTION", "STILL_WINDOW_S", "SETTLE_BAND_DEG",
    "MARTENSITE_XI", "COOLING_WINDOW_S", "REST_SPEED_DEG_S", "window", "first_time", "motion_direction",
    "overshoot_deg", "motion_start_s", "settle_time", "rest_time", "time_to_reach", "martensite_time",
    "cooled_time", "sample_at", "increase", "openloop_metrics", "cooling_phase_metrics",
    "onoff_cycle_metrics", "Span", "segment_metrics",
    "run_metrics", "elapsed_time", "cycle_time", "reached_sum", "reduction",
]
