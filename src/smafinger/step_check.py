"""A run's step checked after it ran: the same run again at half the step.

The numerics a run gets by default were validated against runs at far shorter steps
(:mod:`.engine.numerics`, docs/speed.md), but not on every parameter set: on a light, lightly
damped slider RK4 at its reference step can be over the accuracy budget, most often with no
plausibility warning (docs/speed.md, "The linear rig"). :func:`check_step` runs the same spec
at half the step and half the output interval (the same integrator and PWM model: with the PWM
resolved a sub-step also ends at every output sample, so the interval bounds the sub-steps too)
and compares the mechanism's coordinate at the run's samples.

For an error of order p in the step, a run's own error is about ``r**p / (r**p - 1)`` times its
difference from the run at sub-steps r times shorter (Richardson's estimate). The PWM edges and
the events cut sub-steps whatever the step, so r is measured: the ratio of the two runs'
sub-step counts (2.0 for the long step, 1.5-2.1 for RK4 with the PWM resolved). The check takes
p = 1 (:data:`ASSUMED_ORDER`): the order of the errors the step's decisions make (stick or slip,
branch, reach; docs/speed.md) and of the first-order integrators, so it estimates r / (r - 1)
times the difference (twice it at r = 2), an overestimate where the error is of higher order. A
run whose estimate is over its coordinate's accuracy budget
(:attr:`.parameters.mechanisms.Coordinate.accuracy_rms`, ``accuracy_max``) is flagged; one whose
sub-steps hardly shrank (r below :data:`MIN_REFINEMENT`, a PWM period far below the step) is not
judged: its line says so, with no warning.

What it cannot see: an error that does not shrink from the step to its half (a random search of
the linear rig: 3 of 67 open-loop runs over the budget were not flagged; of the finger joint's
long step, a reach time late by the same tens of milliseconds at 5 and 2.5 ms; docs/speed.md),
and the error of a model choice the step leaves as it is (the averaged PWM against the exact
edges).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

#: the order in the step assumed of a run's error (the module docstring)
ASSUMED_ORDER = 1
#: below this ratio of sub-step counts the check does not judge: its estimate, r / (r - 1) times
#: the difference, would rest on a few per cent of change (21x at 1.05). A PWM period of 0.1 ms
#: on the template rig gives 1.048 (0.5 ms: 1.2; 1 ms: 1.68). On the rig's random search a
#: bound of 1.25 left 24 of 697 moving runs not judged, 1.05 two
MIN_REFINEMENT = 1.05


@dataclass(frozen=True)
class StepCheck:
    """A run against the same run at a shorter step: the coordinate's difference, user unit."""

    signal: str  #: the coordinate's exported name (``theta_deg``, ``position_m``)
    dt_s: float  #: the run's step [s]
    check_dt_s: float  #: the shorter step it was run at again [s]
    rms: float  #: RMS of the difference over the run's samples
    max: float  #: the largest difference
    at_s: float  #: when the largest difference occurred [s]
    budget_rms: float  #: the coordinate's accuracy budget, RMS
    budget_max: float  #: and largest
    substeps: int  #: the run's sub-steps
    check_substeps: int  #: and the other run's

    @property
    def refinement(self) -> float:
        """How many times shorter the other run's sub-steps are, on average (their counts' ratio)."""
        return self.check_substeps / self.substeps if self.substeps else float("nan")

    @property
    def judged(self) -> bool:
        """Whether the sub-steps shrank enough to estimate the error (:data:`MIN_REFINEMENT`)."""
        return self.refinement >= MIN_REFINEMENT

    @property
    def factor(self) -> float:
        """The run's error over the difference (Richardson's, for an error of :data:`ASSUMED_ORDER`;
        NaN where not :attr:`judged`)."""
        if not self.judged:
            return float("nan")
        r = self.refinement ** ASSUMED_ORDER
        return r / (r - 1.0)

    @property
    def estimated_rms(self) -> float:
        return self.factor * self.rms

    @property
    def estimated_max(self) -> float:
        return self.factor * self.max

    @property
    def within(self) -> bool | None:
        """Whether the estimated error is within the budget (both RMS and largest); None where
        not :attr:`judged`."""
        if not self.judged:
            return None
        return self.estimated_rms <= self.budget_rms and self.estimated_max <= self.budget_max

    @property
    def unit(self) -> str:
        return self.signal.rsplit("_", 1)[1]

    def _against(self) -> str:
        return (f"against the same run at dt_s = {self.check_dt_s:g} ({self.check_substeps} sub-steps, "
                f"{self.refinement:.4g}x this run's {self.substeps})")

    def describe(self) -> str:
        """One line: the difference, the estimate and the budget."""
        u = self.unit
        diff = (f"step check: {self.signal} {self._against()}: difference RMS {self.rms:.3g} {u}, max "
                f"{self.max:.3g} {u} (t = {self.at_s:.4g} s)")
        if not self.judged:
            return diff + "; not judged: " + self._unjudged()
        return (diff + f"; the error at dt_s = {self.dt_s:g}, estimated at {self.factor:.3g}x that, is "
                f"{'within' if self.within else 'over'} the budget ({self.budget_rms:g} {u} RMS, "
                f"{self.budget_max:g} {u} max)")

    def _unjudged(self) -> str:
        return (f"its sub-steps hardly shrank (below {MIN_REFINEMENT:g}x): the PWM edges and the output samples "
                f"set them, not the step")

    def warning(self, closed_loop: bool = False) -> str | None:
        """The warning of a run whose estimated error is over the budget (None if within, or not
        :attr:`judged`: no evidence either way, which :meth:`describe` says); ``closed_loop``: the
        run is under a controller, whose loop can amplify differences below any step's error
        (docs/speed.md), so a shorter step need not settle it."""
        if self.within is not False:
            return None
        u = self.unit
        if closed_loop:
            advice = ("a closed loop can amplify differences below any step's error, so a shorter --dt need not "
                      "settle it: read its reach times and overshoots as one run's, and compare statistics over "
                      "runs (docs/speed.md)")
        else:
            advice = f"simulate it at a shorter --dt (dt_s = {self.dt_s / 10:g}, say) and compare"
        return (f"the run has not converged at its step (dt_s = {self.dt_s:g}): {self._against()} its "
                f"{self.signal} differs by {self.rms:.3g} {u} RMS, {self.max:.3g} {u} max (t = {self.at_s:.4g} s); "
                f"its error, estimated at {self.factor:.3g}x that, is over the budget ({self.budget_rms:g} {u} RMS, "
                f"{self.budget_max:g} {u} max); {advice}")

    def to_dict(self) -> dict:
        """JSON-ready: the fields, the refinement, the estimate and whether it is within the
        budget (``factor``, the estimates and ``within`` null where not judged: NaN is not JSON)."""
        judged = self.judged
        return {**dataclasses.asdict(self), "refinement": self.refinement, "judged": judged,
                "factor": self.factor if judged else None,
                "estimated_rms": self.estimated_rms if judged else None,
                "estimated_max": self.estimated_max if judged else None, "within": self.within}


def checked_by_default(params, validated: bool = False) -> bool:
    """Whether ``smafinger simulate`` checks a run's step unless told: where the defaults were not
    validated. On a slider pulled directly by its wire (a wire-slider mode,
    :func:`.engine.numerics.wire_mode_omega`) always: its reference is not validated on every
    set. On the finger joint unless the set is a named one as registered or ``validated`` (a
    named scenario as registered): a random search of changed joint sets found the defaults over
    the budget in 63 of 1,353 runs against a converged reference (docs/cli.md, "The step check"),
    while on the paper's scenarios, where they were validated, the check's estimate raised 3
    false alarms of 56."""
    from .engine.numerics import wire_mode_omega
    from .parameters import is_named

    return wire_mode_omega(params) is not None or not (validated or is_named(params))


#: what a failed check advises by default (``smafinger simulate``'s option)
REMEDY = "--no-check-step skips the check"
#: the same for the Python API's check_step arguments (simulate, Compact)
API_REMEDY = "check_step=False skips the check"


def check_step(result, engine: str = "compiled", progress=False, remedy: str = REMEDY) -> StepCheck:
    """``result``'s coordinate against the same run at half its step.

    Parameters
    ----------
    result : SimulationResult
        A run (decimated or not).
    engine : {"compiled", "interpreted", "auto"}
        The engine of the run at half the step (:func:`smafinger.engine.run.run_spec`).
    progress : bool or smafinger.progress.Display
        Show that run's progress (:func:`smafinger.engine.run.run_spec`).
    remedy : str
        How to skip the check, told when that run stops.

    Returns
    -------
    StepCheck

    Raises
    ------
    TypeError
        ``result`` is not a :class:`~smafinger.results.SimulationResult` (a batch's
        :class:`~smafinger.engine.batch.CompactResult` keeps too little of the run).
    ValueError
        The run's step is one clock tick (1 ns): it has no half.
    SimulationError
        The run at half the step stopped (its message says so).
    """
    from .engine.run import SimulationError, run_spec
    from .results import SimulationResult

    if not isinstance(result, SimulationResult):
        raise TypeError(f"the step check needs a SimulationResult, not a {type(result).__name__}: it reads the "
                        "run's own samples and sub-step count (in a batch: reduce=Compact(check_step=True); in a "
                        "sweep: check_step = true)")
    spec = result.spec
    half = half_step(spec)
    try:
        try:
            other = run_spec(half, progress=progress, engine=engine, record="metrics")
        except ValueError:  # twice the samples over the memory limit (found by review): the run's interval
            half = half_step(spec, halve_output=False)
            other = run_spec(half, progress=progress, engine=engine, record="metrics")
    except SimulationError as exc:  # the same class (DutyNotANumber stays one)
        raise type(exc)(f"step check: the run at dt_s = {spec.dt_s:g} finished, the same run at dt_s = "
                        f"{half.dt_s:g} stopped ({remedy}): {exc}") from None
    coord = spec.params.coordinate
    name = f"{coord.name}_{coord.unit}"
    every = samples_per_sample(spec, half) * result.samples_every
    return compare(spec, result.t, result.signal(name), other.signal(name)[::every], half.dt_s, result.substeps,
                   other.substeps)


def uncheckable(spec) -> str | None:
    """Why ``spec``'s step cannot be checked (None: it can): a step of one clock tick (1 ns) has
    no shorter one."""
    from .engine.clock import to_ticks

    if to_ticks("dt_s", spec.dt_s) < 2:
        return f"dt_s = {spec.dt_s!r} s is the clock's tick (1 ns): there is no shorter step to check it against"
    return None


def half_step(spec, halve_output: bool = True):
    """``spec`` (a :class:`~smafinger.engine.run.RunSpec`) at half its step, to the clock's tick
    below, and (``halve_output``) at half its output interval where that is a whole number of
    ticks (with the PWM resolved, a sub-step ends at every output sample); ValueError where
    :func:`uncheckable` says why not."""
    from .engine.clock import TICK_S, to_ticks

    why = uncheckable(spec)
    if why is not None:
        raise ValueError(why)
    out = to_ticks("output_interval_s", spec.output_interval_s)
    return dataclasses.replace(spec, dt_s=(to_ticks("dt_s", spec.dt_s) // 2) * TICK_S,
                               output_interval_s=(out // 2 if out % 2 == 0 and halve_output else out) * TICK_S)


def samples_per_sample(spec, half) -> int:
    """How many of ``half``'s output samples (:func:`half_step`) one of ``spec``'s spans: the
    stride that reads ``half``'s samples at ``spec``'s times."""
    return round(spec.output_interval_s / half.output_interval_s)


def check_engine(result, setting: str, skip_long: bool = True) -> str | None:
    """The engine of ``result``'s run at half the step under the engine ``setting``: the one
    ``result`` ran on if ``setting`` is ``auto`` (so that the check never compiles in the
    foreground after a run interpreted while the kernel compiles); with ``skip_long``, None where
    that run would be interpreted and is estimated over
    :data:`.engine.interpreted.INTERPRETED_LIMIT_S` (not checked then: run it again once the
    kernel is compiled)."""
    from .engine.interpreted import INTERPRETED_LIMIT_S, interpreted_estimate_s

    if setting != "auto":
        return setting
    if (skip_long and result.engine == "interpreted"
            and interpreted_estimate_s(half_step(result.spec)) > INTERPRETED_LIMIT_S):
        return None
    return result.engine


def compare(spec, t_s, q, q_check, check_dt_s: float, substeps: int, check_substeps: int) -> StepCheck:
    """The :class:`StepCheck` of a run of ``spec`` whose coordinate (user unit) was ``q`` at the
    times ``t_s`` [s], in ``substeps`` sub-steps, and ``q_check`` at the same times when run at
    ``check_dt_s`` in ``check_substeps``."""
    coord = spec.params.coordinate
    diff = np.asarray(q, dtype=np.float64) - np.asarray(q_check, dtype=np.float64)
    i = int(np.argmax(np.abs(diff)))
    return StepCheck(signal=f"{coord.name}_{coord.unit}", dt_s=spec.dt_s, check_dt_s=check_dt_s,
                     rms=float(np.sqrt(np.mean(diff ** 2))), max=float(abs(diff[i])), at_s=float(t_s[i]),
                     budget_rms=coord.accuracy_rms, budget_max=coord.accuracy_max, substeps=int(substeps),
                     check_substeps=int(check_substeps))


def with_step_check(result, engine: str = "compiled", progress=False, remedy: str = REMEDY):
    """``result`` with its :class:`StepCheck` (``result.step_check``) and its metrics as they
    were (a decimated result's are at full resolution), with the check's warning among their
    warnings when the estimate is over the budget (any earlier check's replaced)."""
    chk = check_step(result, engine, progress, remedy)
    m = result.metrics
    old = [] if result.step_check is None else [result.step_check_warning()]
    new = dataclasses.replace(result, step_check=chk)
    warnings = [w for w in m["warnings"] if w not in old] + [w for w in [new.step_check_warning()] if w]
    return dataclasses.replace(new, _metrics={**m, "warnings": warnings})


__all__ = ["API_REMEDY", "ASSUMED_ORDER", "MIN_REFINEMENT", "REMEDY", "StepCheck", "samples_per_sample", "check_engine", "check_step", "checked_by_default", "compare", "half_step",
           "uncheckable", "with_step_check"]
