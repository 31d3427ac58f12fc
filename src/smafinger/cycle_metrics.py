"""Cycle times of a closed-loop run (Fig. 15; issue 3), from its segments' metrics
(:func:`smafinger.metrics.segment_metrics`: ``index``, ``start_s``, ``reached_s``)."""

from __future__ import annotations

from typing import Mapping, Sequence


def _complete(segments: Sequence[Mapping], n_segments: int) -> bool:
    """Every one of the profile's ``n_segments`` segments started (the metrics list those that
    did, in order: a cycle cut short by ``t_end_s`` lacks its last ones) and was reached, but a
    cool-down (``enable`` none: no actuator pursues its target) before the last."""
    return (len(segments) == n_segments > 0 and segments[-1]["reached_s"] is not None
            and all(s["reached_s"] is not None or s.get("enable") == "none" for s in segments))


def elapsed_time(segments: Sequence[Mapping], n_segments: int) -> float | None:
    """Time from 0 at which the last target is reached (start of the last segment plus its
    ``reached_s``); ``None`` unless each of the profile's ``n_segments`` segments started and
    reached its target.

    With targets issued on reach this includes the hold the engine needs to confirm each
    intermediate target before the next segment starts.
    """
    if not _complete(segments, n_segments):
        return None
    return float(segments[-1]["start_s"] + segments[-1]["reached_s"])


def cycle_time(segments: Sequence[Mapping], n_segments: int, n_on_reach: int, hold_s: float) -> float | None:
    """Full-cycle time (issue 3): :func:`elapsed_time` less the ``hold_s`` spent confirming
    the target before each of the ``n_on_reach`` segments that start on reach.

    For a profile whose segments after the first all start on reach this is the sum of the
    segments' ``reached_s``; for a time schedule (``n_on_reach = 0``) it is the elapsed time.
    """
    t = elapsed_time(segments, n_segments)
    return None if t is None else t - n_on_reach * hold_s


def reached_sum(segments: Sequence[Mapping], n_segments: int) -> float | None:
    """Sum of the segments' ``reached_s`` (a cool-down's none); ``None`` unless every one of the
    ``n_segments`` started and was reached (:func:`_complete`)."""
    if not _complete(segments, n_segments):
        return None
    return float(sum(s["reached_s"] for s in segments if s["reached_s"] is not None))


def reduction(slower_s: float | None, faster_s: float | None) -> float | None:
    """Relative time saved: ``(slower - faster) / slower``; ``None`` if either is missing or the
    slower one took no time (no relative saving; it divided by zero)."""
    return None if slower_s is None or faster_s is None or slower_s == 0 else (slower_s - faster_s) / slower_s
