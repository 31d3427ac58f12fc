"""Tune a controller's gains on bench tasks: CMA-ES (``cma``) over a box, each generation one batch.

The objective of a candidate is the mean over its tasks of the task's measure divided by the
paper's PWM-PID's on the same task (so 0.5 is twice as good as the paper): the cycle time for
a ``cycle`` task, the RMS tracking error for the others. Constraints are penalties added to
it: each unreached target 1.0, each interlock violation 1.0. The peak temperature is a hard
limit, not a trade: ``max_peak_T_C`` (default: the paper's PID's own peak on the same tasks,
so a tuned controller may not heat the wires more than the paper's does). A task whose hottest
wire exceeds it costs a step of 1.0 plus 1.0 per degC over. The step is the paper's PID's whole
measure, so a candidate over the limit (measure > 0, plus at least 1.0) ranks below every
candidate within it that is at least as good as the paper's PID (objective at most 1.0), i.e.
below every candidate a tuning could return as an improvement, however much faster it is (on
one task, as the bench's tunings are; over several tasks it is averaged like every penalty). The
slope ranks over-limit candidates by how far over they are, which leads the search back inside.
CMA-ES uses only the ranks of the objectives, so a step does not hamper it. A candidate whose
values are inconsistent (a fuzzy K_P_min above K_P_max) is not run and scores :data:`INVALID`.

Free parameters (:class:`FreeParam`) live in a box; gains are searched on a log scale. Every
candidate is an ordinary bench run (:func:`smafinger.engine.batch.run_batch`), so a tuning is
deterministic for a given seed and independent of the number of workers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from ..control.params import CONTROLLERS, ControllerParameters, PaperPID
from ..engine.batch import make_pool, run_batch
from ..model.build import build_model
from ..parameters import ParameterError, ParameterSet
from ..values import is_real, is_whole, one_or_many
from .runner import BENCH_NUMERICS, OUTPUT_S, warm_kernels
from .scores import record_of, task_scores
from .tasks import Task

#: penalty weights (objective units: 1.0 = the paper's PID on a task)
UNREACHED_PENALTY = 1.0
VIOLATION_PENALTY = 1.0
#: a task over the peak temperature limit: a step, plus a slope per degC over
HEAT_STEP_PENALTY = 1.0
HEAT_PENALTY_PER_C = 1.0
#: the objective of a candidate whose values are inconsistent (no run made)
INVALID = 100.0


@dataclass(frozen=True)
class FreeParam:
    """A tuned field, searched in [lo, hi] (on a log scale if ``log``)."""

    name: str
    lo: float
    hi: float
    log: bool = False

    def __post_init__(self):
        if not (math.isfinite(self.lo) and math.isfinite(self.hi) and self.lo < self.hi):
            raise ValueError(f"{self.name}: bounds {self.lo:g}:{self.hi:g} must be finite with lo < hi")
        if self.log and self.lo <= 0.0:
            raise ValueError(f"{self.name}: a log-scale bound must be positive, not {self.lo:g}")

    def value(self, u: float) -> float:
        """The value at position u in [0, 1] of the box."""
        u = min(max(u, 0.0), 1.0)
        if self.log:
            return math.exp(math.log(self.lo) + u * (math.log(self.hi) - math.log(self.lo)))
        return self.lo + u * (self.hi - self.lo)

    def position(self, v: float) -> float:
        """The position of ``v`` in the box (below 0 or above 1 outside it; a value of 0 or less on
        a log scale is at its low end: a valid gain of 0 took log(0))."""
        if self.log:
            if v <= 0.0:
                return 0.0
            return (math.log(v) - math.log(self.lo)) / (math.log(self.hi) - math.log(self.lo))
        return (v - self.lo) / (self.hi - self.lo)

    @classmethod
    def parse(cls, text: str) -> "FreeParam":
        """``NAME=LO:HI`` (linear) or ``NAME=LO:HI:log``."""
        try:
            name, rng = text.split("=", 1)
            parts = rng.split(":")
            log = len(parts) == 3 and parts[2].strip().lower() == "log"
            if len(parts) not in (2, 3) or (len(parts) == 3 and not log):
                raise ValueError
            return cls(name.strip(), float(parts[0]), float(parts[1]), log)
        except ValueError:
            raise ValueError(f"--param {text!r} is not NAME=LO:HI or NAME=LO:HI:log") from None


def default_free(label: str, p: ParameterSet) -> tuple[FreeParam, ...]:
    """The fields tuned by default, their boxes scaled from the set's own PID gains."""
    g = build_model(p).controller
    kp, kv, ki = (max(x, 1e-9) for x in (g.K_P, g.K_V, g.K_I))
    pid = (FreeParam("K_P_per_q", kp / 10, kp * 10, True), FreeParam("K_V_s_per_q", kv / 30, kv * 3, True),
           FreeParam("K_I_per_q_s", ki / 10, ki * 30, True))
    if label in ("pid", "resistance"):
        return pid
    if label == "fuzzy-pid":
        return (FreeParam("K_P_min_per_q", kp / 10, kp * 3, True), FreeParam("K_P_max_per_q", kp / 3, kp * 10, True),
                FreeParam("K_V_min_s_per_q", kv / 100, kv, True), FreeParam("K_V_max_s_per_q", kv / 30, kv * 3, True),
                FreeParam("e_span_q", 30 / kp, 3000 / kp, True), FreeParam("de_span_q_s", 30 / kv, 3000 / kv, True))
    if label == "sliding-mode":
        return (FreeParam("lambda_per_s", 0.1, 20.0, True), FreeParam("lambda_I_per_s2", 1e-3, 1.0, True),
                FreeParam("phi_q_per_s", 1.0 / kv, 1000.0 / kv, True), FreeParam("K_pct", 20.0, 100.0))
    if label == "rapid-heating":
        return pid + (FreeParam("boost_V", p.V_H_V, 2.0 * p.V_H_V), FreeParam("boost_until_C", p.A_S0_C - 30.0,
                                                                             p.A_F0_C))
    raise ValueError(f"controller {label!r} is not one of {', '.join(CONTROLLERS)}")


@dataclass
class TuneResult:
    label: str
    values: dict  #: the best candidate's free fields
    objective: float
    scores: list  #: the best candidate's scores per task
    reference: list  #: the paper's PID's scores per task
    max_peak_T_C: float
    evaluations: int
    history: list = field(default_factory=list)  #: best objective after each generation

    def controller(self, base: ControllerParameters) -> ControllerParameters:
        return base.replace(**self.values)


def task_measure(task: Task, scores: dict) -> float | None:
    """The measure a task is tuned on: its cycle time (cycle tasks) or its RMS error."""
    return scores.get("cycle_s") if task.kind == "cycle" else scores["rms_error"]


def heat_penalty(peak_T_C: float, max_peak_T_C: float) -> float:
    """The penalty of a task whose hottest wire peaked at ``peak_T_C``: 0 within the limit, else a
    step of :data:`HEAT_STEP_PENALTY` plus :data:`HEAT_PENALTY_PER_C` per degC over."""
    over = peak_T_C - max_peak_T_C
    return HEAT_STEP_PENALTY + HEAT_PENALTY_PER_C * over if over > 0.0 else 0.0


def objective(tasks: Sequence[Task], scores: Sequence[dict], reference: Sequence[dict], max_peak_T_C: float) -> float:
    """The tuning objective of one candidate (see the module docstring)."""
    total = 0.0
    for task, s, ref in zip(tasks, scores, reference):
        m, m_ref = task_measure(task, s), task_measure(task, ref)
        if m is None:  # a cycle never completed: as slow as the whole run, and penalised
            m = task.t_end_s
        total += m / m_ref if m_ref else m
        total += UNREACHED_PENALTY * s.get("unreached", 0) + VIOLATION_PENALTY * s["interlock_violations"]
        total += heat_penalty(s["peak_T_C"], max_peak_T_C)
    return total / len(tasks)


def _specs(tasks, controllers, strategy) -> list:
    from ..engine.run import make_spec

    return [make_spec(t.params(), strategy, t.profile, t_end_s=t.t_end_s, output_interval_s=OUTPUT_S, controller=c,
                      **BENCH_NUMERICS)
            for c in controllers for t in tasks]


def _scores(tasks, controllers, strategy, pool) -> list[list[dict] | None]:
    """Each controller's scores per task; ``None`` for a controller whose values are inconsistent
    (e.g. a fuzzy K_P_min above its K_P_max: a :class:`ParameterError` when its record is built)."""
    valid = []
    for c in controllers:
        try:
            _specs(tasks, [c], strategy)
            valid.append(c)
        except ParameterError:
            valid.append(None)
    ok = [c for c in valid if c is not None]
    recs = run_batch(_specs(tasks, ok, strategy), reduce=record_of, pool=pool) if ok else []
    n, out, k = len(tasks), [], 0
    for c in valid:
        if c is None:
            out.append(None)
        else:
            out.append([task_scores(t, r) for t, r in zip(tasks, recs[k * n:(k + 1) * n])])
            k += 1
    return out


def tune(base: ControllerParameters, tasks: Sequence[Task], strategy: str = "cooperative",
         free: Sequence[FreeParam] | None = None, max_peak_T_C: float | None = None, budget: int = 120,
         popsize: int = 10, seed: int = 1, workers: int | None = None,
         report: Callable[[str], None] | None = None, fixed: Sequence[str] = ()) -> TuneResult:
    """CMA-ES on the free fields of ``base`` over ``tasks`` (one mechanism); see the module docstring.

    ``fixed``: fields given their values (``--set``): left out of the default free fields, and
    refused among explicit ones (the search would tune a value reported as fixed)."""
    _check_search(budget, popsize, max_peak_T_C, free)
    fixed = one_or_many(fixed)  # one name is a list of one (its letters were 'fixed': found by review)
    say = report or (lambda msg: None)
    mechs = {t.mechanism for t in tasks}
    if len(mechs) != 1:
        raise ValueError(f"tune on one mechanism at a time, not {', '.join(sorted(mechs))}")
    p = tasks[0].params()
    base = base.prepared(p)
    if free is not None:
        both = sorted({f.name for f in free} & set(fixed))
        if both:
            raise ValueError(f"{both[0]} is both fixed (--set) and free (--param): give it one way")
        free = tuple(free)
    else:
        free = tuple(f for f in default_free(base.label, p) if f.name not in set(fixed))
    known = set(base.field_names())
    for f in free:
        if f.name not in known:
            raise ValueError(f"{base.label} has no tunable field {f.name!r} (known: {', '.join(sorted(known))})")
    warm_kernels(_specs(tasks[:1], [PaperPID(), base], strategy))  # compiled once here, loaded by the workers
    with make_pool(workers) as pool:
        return _search(base, tasks, strategy, free, max_peak_T_C, budget, popsize, seed, pool, say)


#: the smallest budget (evaluations) and population CMA-ES is run with (cma needs 2 weights)
MIN_BUDGET, MIN_POPSIZE = 1, 2


def _check_search(budget, popsize, max_peak_T_C, free) -> None:
    """ValueError naming a search setting :func:`tune` cannot use (found by an API fuzz: a budget
    of 0 returned no values, a NaN limit turned the temperature limit off, no free field divided
    by zero inside cma)."""
    for name, v, lo in (("budget", budget, MIN_BUDGET), ("popsize", popsize, MIN_POPSIZE)):
        if not (is_whole(v) and v >= lo):
            raise ValueError(f"{name} = {v!r} must be a whole number >= {lo}")
    if max_peak_T_C is not None and not (is_real(max_peak_T_C) and math.isfinite(max_peak_T_C)):
        raise ValueError(f"max_peak_T_C = {max_peak_T_C!r} must be a finite temperature in degC")
    if free is not None and len(free) == 0:
        raise ValueError("free: no field to tune (give one at least, or None for the default ones)")


def _search(base, tasks, strategy, free, max_peak_T_C, budget, popsize, seed, pool, say) -> TuneResult:
    import cma

    reference = _scores(tasks, [PaperPID()], strategy, pool)[0]
    limit = max(s["peak_T_C"] for s in reference) if max_peak_T_C is None else float(max_peak_T_C)
    say(f"paper's PID: {', '.join(f'{t.name} {task_measure(t, s):.4g}' for t, s in zip(tasks, reference))}; "
        f"peak temperature limit {limit:.2f} degC")
    x0 = [min(max(f.position(getattr(base, f.name)), 0.0), 1.0) if getattr(base, f.name) is not None else 0.5
          for f in free]
    es = cma.CMAEvolutionStrategy(x0, 0.25, {"bounds": [0.0, 1.0], "popsize": popsize, "seed": seed,
                                             "maxfevals": budget, "verbose": -9})
    best = (math.inf, None, None)
    history, evaluations = [], 0
    while not es.stop() and evaluations < budget:
        # the last generation cut to what is left of the budget (CMA-ES then learns nothing from
        # it: its update needs a whole population; it may still hold the best candidate)
        xs = es.ask()[:budget - evaluations]
        cands = [base.replace(**{f.name: f.value(u) for f, u in zip(free, x)}) for x in xs]
        all_scores = _scores(tasks, cands, strategy, pool)
        fs = [INVALID if s is None else objective(tasks, s, reference, limit) for s in all_scores]
        if len(xs) == es.popsize:
            es.tell(xs, fs)
        evaluations += len(xs)
        k = int(np.argmin(fs))
        if fs[k] < best[0]:
            best = (fs[k], {f.name: f.value(u) for f, u in zip(free, xs[k])}, all_scores[k])
        history.append(best[0])
        say(f"{evaluations} evaluations: best objective {best[0]:.4f}")
    return TuneResult(base.label, best[1], best[0], best[2], reference, limit, evaluations, history)
