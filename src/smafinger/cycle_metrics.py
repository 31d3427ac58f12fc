"""Cycle times of a closed-loop run (Fig. 15; issue 3), from its segments' metrics
(:func:`smafinger.metrics.segment_metrics`: ``index``, ``start_s``, ``reached_s``)."""

from __future__ import annotations

from typing import Mapping, Sequence


def elapsed_time(segments: Sequence[Mapping]) -> float | None:
    """Time from 0 at which the last target is reached (start of the last segment plus its
    ``reached_s``); ``None`` if a segment never started or the last target was not reached.

    With targets issued on reach this includes the hold the engine needs to confirm each
    intermediate target before the next segment starts.
    """
    if not segments or segments[-1]["reached_s"] is None or len(segments) != segments[-1]["index"] + 1:
        return None
    return float(segments[-1]["start_s"] + segments[-1]["reached_s"])


def cycle_time(segments: Sequence[Mapping], n_on_reach: int, hold_s: float) -> float | None:
    """Full-cycle time (issue 3): :func:`elapsed_time` less the ``hold_s`` spent confirming
    the target before each of the ``n_on_reach`` segments that start on reach.

    For a profile whose segments after the first all start on reach this is the sum of the
    segments' ``reached_s``; for a time schedule (``n_on_reach = 0``) it is the elapsed time.
    """
    t = elapsed_time(segments)
    return None if t is None else t - n_on_reach * hold_s


def reached_sum(segments: Sequence[Mapping]) -> float | None:
    """Sum of the segments' ``reached_s``; ``None`` if one was not reached."""
    rs = [s["reached_s"] for s in segments]
    return None if not rs or any(r is None for r in rs) else float(sum(rs))


def reduction(slower_s: float | None, faster_s: float | None) -> float | None:
    """Relative time saved: ``(slower - faster) / slower``; ``None`` if either is missing."""
    return None if slower_s is None or faster_s is None else (slower_s - faster_s) / slower_s
