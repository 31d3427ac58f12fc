"""A scenario's figure metrics (the numbers its claims read), and a finished run.

Each scenario names the figure metrics it needs with one of the typed derivations below;
:func:`derive` computes them from a :class:`~smafinger.results.SimulationResult` with
the definitions of :mod:`smafinger.metrics`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Union

from .. import metrics as M
from ..engine.run import RunSpec
from ..results import SimulationResult

if TYPE_CHECKING:  # the scenario names its derivation: no import at run time
    from .scenario import Scenario

WIRES = ("upper", "lower")


def cycle_metrics(result: SimulationResult) -> dict:
    """A closed-loop run's cycle times: ``cycle_s`` (:func:`~smafinger.metrics.cycle_time`),
    ``elapsed_s`` (time from 0) and ``reached_sum_s``."""
    segs = result.summary()["segments"]
    n = len(result.spec.profile.segments)
    n_on_reach = sum(1 for s in result.spec.profile.segments if s.start_s is None)
    return {"cycle_s": M.cycle_time(segs, n, n_on_reach, result.spec.hold_s),
            "elapsed_s": M.elapsed_time(segs, n), "reached_sum_s": M.reached_sum(segs, n)}


def segment_detail(result: SimulationResult, index: int) -> dict:
    """A segment's target, start, end, reach time and overshoot (from the run's metrics); its
    settling time (:func:`~smafinger.metrics.settle_time`), when the joint comes to rest
    (:func:`~smafinger.metrics.rest_time`), when the wires it started with partly austenite are
    back to martensite (``cooled_s``, :func:`~smafinger.metrics.cooled_time`; 0 if none was),
    the later of that and its reach time (``reached_cooled_s``), the angle at its
    end; and per wire when it got back to martensite and its peak duty."""
    seg = next(s for s in result.summary()["segments"] if s["index"] == index)
    t, th = result.t, result.signal("theta_deg")
    a, b = seg["start_s"], seg["end_s"]
    inside = M.window(t, a, b)
    xi = {w: result.signal(f"xi_{w}") for w in WIRES}
    out = {k: seg[k] for k in ("target_deg", "start_s", "end_s", "reached_s", "overshoot_deg")}
    out["settle_s"] = M.settle_time(t, th, seg["target_deg"], a, b)
    out["rest_s"] = M.rest_time(t, result.signal("omega_deg_s"), a, b)
    out["cooled_s"] = M.cooled_time(t, xi, a, b)
    # over when reached and cooled (cooled alone is 0 for a move that began all martensite)
    out["reached_cooled_s"] = None if None in (out["reached_s"], out["cooled_s"]) else max(out["reached_s"],
                                                                                          out["cooled_s"])
    out["final_deg"] = float(th[inside][-1])
    for w in WIRES:
        out[f"martensite_{w}_s"] = M.martensite_time(t, xi[w], a)
        out[f"peak_duty_{w}"] = float(result.signal(f"duty_{w}")[inside].max())
    return out


@dataclass(frozen=True)
class OpenLoop:
    """Open loop, heated until ``t_off_s`` then cooling (Sec. 3.1):
    :func:`~smafinger.metrics.openloop_metrics`."""

    t_off_s: float

    def compute(self, result: SimulationResult) -> dict:
        return M.openloop_metrics(result.t, result.signal("theta_deg"), self.t_off_s)


@dataclass(frozen=True)
class Cycle:
    """Closed loop: the cycle times (:func:`cycle_metrics`) and every segment that started,
    in detail (``moves``: :func:`segment_detail` of each)."""

    def compute(self, result: SimulationResult) -> dict:
        moves = [segment_detail(result, s["index"]) for s in result.summary()["segments"]]
        return {**cycle_metrics(result), "moves": moves}


@dataclass(frozen=True)
class OnOffCycles:
    """Open loop, ``wire`` switched on and off (Sec. 3.2, Fig. 10a): the cycles of
    :func:`~smafinger.metrics.onoff_cycle_metrics` (``cycles``), ``on_s`` the (on, off) times."""

    on_s: tuple[tuple[float, float], ...]
    wire: str = "upper"

    def compute(self, result: SimulationResult) -> dict:
        w = self.wire
        return {"cycles": M.onoff_cycle_metrics(
            result.t, result.signal("theta_deg"), result.signal(f"T_{w}_C"), result.signal(f"T_casing_{w}_C"),
            result.signal(f"xi_{w}"), self.on_s)}


@dataclass(frozen=True)
class MoveAndReturn:
    """A move (segment 0) and the return from it (segment ``return_segment``): the cycle
    times and :func:`segment_detail` of both (keys ``move`` and ``return``)."""

    return_segment: int = 1

    def compute(self, result: SimulationResult) -> dict:
        return {**cycle_metrics(result), "return": segment_detail(result, self.return_segment),
                "move": segment_detail(result, 0)}


@dataclass(frozen=True)
class CoolingPhase:
    """The ``wire``'s first cooling phase, the joint past ``target_deg`` (Fig. 11):
    the cycle times and :func:`~smafinger.metrics.cooling_phase_metrics` (``cooling_phase``)."""

    target_deg: float
    wire: str = "upper"

    def compute(self, result: SimulationResult) -> dict:
        cp = M.cooling_phase_metrics(result.t, result.signal("theta_deg"),
                                     result.signal(f"T_{self.wire}_C"), self.target_deg)
        return {**cycle_metrics(result), "cooling_phase": cp}


Derivation = Union[OpenLoop, Cycle, MoveAndReturn, CoolingPhase, OnOffCycles]


@dataclass
class Run:
    """One finished run: its key, spec, summary, figure metrics and (thinned) result.

    ``summary`` and ``derived`` are computed from the full-resolution output; ``result``
    is what the CSVs and the figures use. A failed run keeps its ``error``.
    """

    key: str
    spec: RunSpec
    result: SimulationResult | None
    summary: dict | None
    derived: dict | None = None
    error: str | None = None
    scenario: "Scenario | None" = None

    @property
    def ok(self) -> bool:
        return self.error is None


def derive(derivation: Derivation | None, result: SimulationResult) -> dict:
    """The figure metrics ``derivation`` names ({} for none)."""
    return {} if derivation is None else derivation.compute(result)


__all__ = ["OpenLoop", "Cycle", "MoveAndReturn", "CoolingPhase", "OnOffCycles", "Derivation", "Run", "derive",
           "cycle_metrics", "segment_detail"]
