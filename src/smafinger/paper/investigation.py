"""The Fig. 15 full-cycle investigation of smafinger 0.1: readings of the paper, each a change
from the v1 on-reach baseline (whose independent strategy uses the antagonist once the agonist's
wire is back to martensite), as typed data. The faithful runs, the damping rules and the
readings of the co-operative time are in :mod:`.cycle_study`.

A :class:`Reading` changes the Fig. 15 on-reach scenarios (``fig15-*-v1``) with
:class:`~.overrides.Overrides` per strategy; ``cooperative = None`` means the reading only
concerns the independent strategy and shares the baseline's co-operative run. Its
``topic`` groups it in the report's findings (:mod:`.findings`). Adding a reading is one
entry in :data:`READINGS`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

from ..engine.run import RunSpec
from ..metrics import reduction
from . import studies
from .derived import Cycle, Derivation, Run
from .fig15 import REACH_V1 as REACH
from .fig15 import SCHEDULE_T_END_S, TARGETS, on_reach, scheduled
from .overrides import Overrides
from .scenario import MOVE_S
from .scenarios import get
from .fig11 import WARM_C

#: simulated time of the investigation's runs [s]
T_END_S = 80.0
#: their figure metrics
DERIVE = Cycle()
TOPICS = ("wait", "reached", "temperature", "controller", "schedule")


@dataclass(frozen=True)
class Reading:
    """One reading: what it changes (``label``; ``short`` in sentences) and how."""

    key: str
    label: str
    short: str
    topic: str
    independent: Overrides = Overrides()
    cooperative: Overrides | None = Overrides()

    def __post_init__(self) -> None:
        if self.topic not in TOPICS:
            raise ValueError(f"reading {self.key!r}: topic {self.topic!r} is not one of {', '.join(TOPICS)}")


def _both(key: str, label: str, short: str, topic: str, **changes) -> Reading:
    ov = Overrides.of(**changes)
    return Reading(key, label, short, topic, ov, ov)


_BASE = get(REACH["independent"]).spec()
_SCHEDULE = dict(t_end_s=SCHEDULE_T_END_S)

READINGS: tuple[Reading, ...] = (
    Reading("baseline", f"as specified: next target once the previous one is within {_BASE.tol_deg:g} deg for "
            f"{_BASE.hold_s:g} s; independent uses the antagonist once the agonist wire is back to martensite",
            "once the agonist's wire is back to martensite (the engine's rule)", "wait"),
    _both("tol0.2", f"'reached' = within 0.2 deg for {_BASE.hold_s:g} s", "within 0.2 deg", "reached", tol_deg=0.2),
    _both("tol0.1", f"'reached' = within 0.1 deg for {_BASE.hold_s:g} s", "within 0.1 deg", "reached", tol_deg=0.1),
    _both("hold2", f"'reached' = within {_BASE.tol_deg:g} deg for 2 s (a 2 s hold at each target)",
          "a 2 s hold at each target", "reached", hold_s=2.0),
    Reading("nowait", "independent: antagonist enabled at once (no wait for the agonist's cooling)",
            "at once", "wait", Overrides.of(independent_wait=False), None),
    Reading("via-rest", f"independent: back to {TARGETS['independent'][1]:g} deg (reached) before the antagonist "
            "is used (Sec. 4.1's sequence " + ", ".join(f"{t:g}" for t in TARGETS["independent"]) + ")",
            "once the joint is back at the rest position (Sec. 4.1's sequence)", "wait",
            Overrides.of(profile=on_reach(TARGETS["independent"])), None),
    _both("Tinit60", f"initial wire temperature {WARM_C:g} degC (ambient {_BASE.params.T_amb_C:g} degC)",
          f"wires starting at {WARM_C:g} degC", "temperature", T_init_C=WARM_C),
    _both("Tamb60", f"initial and ambient temperature {WARM_C:g} degC (the authors' 2020 model)",
          f"ambient and initial {WARM_C:g} degC (the authors' 2020 model)", "temperature",
          T_init_C=WARM_C, T_amb_C=WARM_C),
    _both("update0", f"controller updated at every step instead of every {_BASE.params.controller_update_s:g} s",
          "continuous update", "controller", controller_update_s=0.0),
    _both("coolingoff", "controller switched off in the cooling phase", "controller off in cooling", "controller",
          controller_in_cooling=False),
    _both("antiwindup", "anti-windup (conditional integration)", "anti-windup", "controller", anti_windup="clamp"),
    _both("intnever", "error integral never reset (the authors' 2020 model)", "integral never reset",
          "controller", integral_reset="never"),
    _both("restick", "friction: the joint re-sticks whenever it stops (smafinger 0.1's default for paper2010)",
          "re-sticking friction", "controller", friction_sticking="restick"),
    _both("sched-direct", f"time schedule, one move every {MOVE_S:g} s; independent goes "
          f"{TARGETS['cooperative'][0]:g} -> {TARGETS['cooperative'][1]:g} directly (engine's wait for the "
          "agonist's cooling)", "without the stop at the rest position", "schedule",
          profile=scheduled(TARGETS["cooperative"]), **_SCHEDULE),
    Reading("sched", f"time schedule, one move every {MOVE_S:g} s; independent through the rest position "
            f"(Sec. 4.1), co-operative " + ", ".join(f"{t:g}" for t in TARGETS["cooperative"])
            + " (the *-scheduled-v1 scenarios)", "through the rest position (Sec. 4.1)", "schedule",
            Overrides.of(profile=scheduled(TARGETS["independent"]), **_SCHEDULE),
            Overrides.of(profile=scheduled(TARGETS["cooperative"]), **_SCHEDULE)),
)


def reading(key: str) -> Reading:
    """The reading called ``key``."""
    for r in READINGS:
        if r.key == key:
            return r
    raise ValueError(f"unknown reading {key!r} (known: {', '.join(r.key for r in READINGS)})")


def run_key(rd: Reading, strategy: str) -> str:
    """The key of a reading's run (the baseline's co-operative run where it is shared)."""
    if strategy == "cooperative" and rd.cooperative is None:
        return run_key(READINGS[0], strategy)
    return f"inv:{rd.key}:{strategy}"


def spec(rd: Reading, strategy: str) -> RunSpec:
    """The run of reading ``rd`` for ``strategy``: its Fig. 15 scenario, changed."""
    ov = rd.independent if strategy == "independent" else rd.cooperative
    return get(REACH[strategy]).spec(Overrides.of(t_end_s=T_END_S).then(ov))


def reading_tasks() -> list[tuple[str, RunSpec]]:
    """``(key, spec)`` of every run of the v1 readings."""
    return [(run_key(rd, k), spec(rd, k)) for rd in READINGS for k in ("independent", "cooperative")
            if k == "independent" or rd.cooperative is not None]


def needed_scenarios() -> tuple[str, ...]:
    """The scenarios whose runs the investigation's tables read: the v1 on-reach pair the
    readings vary and every study's scenarios. Run without one, its cells would say ``never``
    (not completed) for a run that was never made."""
    return tuple(dict.fromkeys([*REACH.values(), *(n for s in studies.STUDIES for n in s.scenarios)]))


def tasks(names: Iterable[str] | None = None) -> list[tuple[str, RunSpec]]:
    """``(key, spec)`` of every run of the investigation: the v1 readings and the studies'
    variants (:mod:`.studies`; of the scenarios ``names`` only, if given)."""
    return reading_tasks() + studies.tasks(names)


def derivations() -> dict[str, Derivation | None]:
    """The figure metrics of every investigation run, by key."""
    out: dict[str, Derivation | None] = {k: DERIVE for k, _ in reading_tasks()}
    out.update(studies.derivations())
    return out


def table(runs: dict[str, Run]) -> list[dict]:
    """One row per reading: cycle times, reduction, each segment's reached_s, the largest
    co-operative overshoot and the interlock violations."""
    rows = []
    for rd in READINGS:
        pair = {k: runs.get(run_key(rd, k)) for k in ("independent", "cooperative")}
        ok = {k: r if r is not None and r.ok else None for k, r in pair.items()}
        t = {k: None if r is None else r.derived["cycle_s"] for k, r in ok.items()}
        seg = {k: None if r is None else [s["reached_s"] for s in r.summary["segments"]] for k, r in ok.items()}
        coop = ok["cooperative"]
        rows.append({
            "key": rd.key, "reading": rd.label, "topic": rd.topic,
            "independent_s": t["independent"], "cooperative_s": t["cooperative"],
            "cooperative_overshoot_deg": None if coop is None else max(s["overshoot_deg"] for s in coop.summary["segments"]),
            "reduction": reduction(t["independent"], t["cooperative"]),
            "independent_reached_s": seg["independent"], "cooperative_reached_s": seg["cooperative"],
            "cooperative_shared_with_baseline": rd.cooperative is None,
            "interlock_violations": sum(r.summary["interlock_violations"] for r in ok.values() if r is not None),
        })
    return rows


__all__ = ["Reading", "READINGS", "T_END_S", "DERIVE", "reading", "run_key", "spec", "reading_tasks", "tasks",
           "derivations", "table"]
