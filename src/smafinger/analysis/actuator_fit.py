"""Fit the named parameters of an actuator's set to several bench runs at once.

Two stages, both in the unit box of :class:`~.free_params.FreeBox`, on the objective of
:class:`~.actuator_eval.Evaluator` (every fitted run simulated in full, a sensor offset per run
profiled out):

1. **global**: CMA-ES (:mod:`cma`, bounded, seeded) on the sum of squares. Each generation's
   candidates times the runs go to the batch engine as one batch, so they run in parallel. It
   finds the right region from a poor start, where a local method would stall (a wire that never
   reaches its transformation band in the model leaves the position flat: no gradient).
2. **local**: :func:`scipy.optimize.least_squares` (trust-region reflective, bounds [0, 1])
   from the best point found, with a Jacobian of central differences of ``diff_step`` in the
   unit box (secants: the engine's discrete events, such as the PWM edges, kinetics branch
   switches and restick, make the model piecewise smooth on small scales), its 2n points in
   one batch.

Uncertainties: the Jacobian at the solution, in the fitted values and the offsets jointly,
and the residuals give the covariance of :func:`~.fit_uncertainty.covariance`: AR(1)
residuals per run (sandwich), with the independent-residual one beside it. A fitted value the
runs do not determine (a singular Jacobian, or a standard error more than
:data:`~.fit_uncertainty.UNDETERMINED_WIDTHS` times the width of its bounds:
:func:`~.fit_uncertainty.mark_undetermined`) gets an infinite standard error and a note.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
from scipy.optimize import least_squares

from ..engine.defaults import DEFAULT_DT_S, FIT_BUDGET, FIT_MAX_NFEV, FIT_SEED
from ..parameters import ParameterSet
from ..values import is_real, is_whole
from .actuator_eval import Evaluator
from .bench_runs import BenchRun
from .fit_uncertainty import (DETERMINED_CHI2, UNDETERMINED_WIDTHS, Covariance, covariance, flat_within_bounds,
                               mark_undetermined, marked)
from .free_params import FreeBox, FreeParameter

UNCERTAINTY_METHOD = (
    "Linearised at the solution: Jacobian by central differences (step diff_step in the unit box) "
    "of the simulated output with respect to the fitted values and one sensor offset per fitted run, "
    "jointly. Residuals are autocorrelated (sampled smooth signals, model misfit), so each run's "
    "residuals are modelled as AR(1) with their own variance and lag-1 autocorrelation rho, and the "
    "covariance is the sandwich (J'J)^-1 J' S J (J'J)^-1 with S_ij = s^2 rho^|i-j| within a run "
    "(stderr); stderr_white assumes independent residuals of one variance, s^2 (J'J)^-1.")


#: the least-squares stage restarts while a run lowers the sum of squares by more than this fraction
RESTART_GAIN = 1e-3
MAX_RESTARTS = 3


class FitError(RuntimeError):
    """The fit could not produce a usable result (every candidate failed, say)."""


@dataclass(frozen=True)
class FitSettings:
    """Budgets and steps of the two stages.

    Attributes
    ----------
    budget : int
        Candidate sets the global stage may evaluate (0: skip it).
    popsize : int or None
        CMA-ES population (default: cma's, 4 + 3 ln n).
    sigma0 : float
        CMA-ES initial step in the unit box.
    seed : int
        Seed of CMA-ES (its random numbers; the global numpy state is restored afterwards).
    max_nfev : int
        Iterations allowed to the least-squares stage.
    diff_step : float
        Finite-difference half-width in the unit box (Jacobians).
    dt_s : float
        Integration step of every simulation.
    fit_offsets : bool
        Fit a sensor offset per run (profiled out), or take the output as calibrated.
    """

    budget: int = FIT_BUDGET
    popsize: int | None = None
    sigma0: float = 0.25
    seed: int = FIT_SEED
    max_nfev: int = FIT_MAX_NFEV
    diff_step: float = 1e-2
    dt_s: float = DEFAULT_DT_S
    fit_offsets: bool = True

    def __post_init__(self) -> None:
        """ValueError naming a setting the two stages cannot use (found by an API fuzz: max_nfev 0
        an AttributeError, sigma0 0 a division by zero in cma, a diff_step of 0 a parameter
        reported 'not determined', a max_nfev of 1.5 no budget at all)."""
        for name, lo in (("budget", 0), ("max_nfev", 1), ("seed", 0)):
            v = getattr(self, name)
            if not (is_whole(v) and v >= lo):
                raise ValueError(f"fit settings: {name} = {v!r} must be a whole number >= {lo}")
        if self.popsize is not None and not (is_whole(self.popsize) and self.popsize >= 2):
            raise ValueError(f"fit settings: popsize = {self.popsize!r} must be a whole number >= 2 (or None)")
        for name, hi in (("sigma0", 1.0), ("diff_step", 0.5), ("dt_s", 1.0)):
            v = getattr(self, name)
            if not (is_real(v) and 0.0 < v <= hi):
                raise ValueError(f"fit settings: {name} = {v!r} must be a number in (0, {hi:g}]")


@dataclass
class ActuatorFit:
    """What a fit found; :meth:`to_dict` is the report's ``fit`` section."""

    free: tuple[FreeParameter, ...]
    params: ParameterSet
    start: dict[str, float]
    values: dict[str, float]
    stderr: dict[str, float]
    stderr_white: dict[str, float]
    correlation: list[list[float]]
    offsets: dict[str, float]
    offset_stderr: dict[str, float | None]
    rho: dict[str, float]
    rms_start: float
    rms: float
    at_bounds: list[str]
    stages: list[dict]
    n_simulations: int
    wall_s: float
    rank_deficient: bool
    settings: FitSettings
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        s = self.settings
        return {
            "free": [{"name": f.name, "lo": f.lo, "hi": f.hi, "scale": "log" if f.log else "linear",
                      "start": self.start[f.name], "value": self.values[f.name], "stderr": self.stderr[f.name],
                      "stderr_white": self.stderr_white[f.name]} for f in self.free],
            "values": self.values, "stderr": self.stderr, "stderr_white": self.stderr_white,
            "correlation": {"names": [f.name for f in self.free], "matrix": self.correlation},
            "uncertainty_method": UNCERTAINTY_METHOD, "rank_deficient": self.rank_deficient,
            "offsets": self.offsets, "offset_stderr": self.offset_stderr, "lag1_autocorrelation": self.rho,
            "rms_start": self.rms_start, "rms": self.rms, "at_bounds": self.at_bounds, "stages": self.stages,
            "n_simulations": self.n_simulations, "wall_s": self.wall_s,
            "settings": {"budget": s.budget, "popsize": s.popsize, "sigma0": s.sigma0, "seed": s.seed,
                         "max_nfev": s.max_nfev, "diff_step": s.diff_step, "dt_s": s.dt_s,
                         "fit_offsets": s.fit_offsets},
            "notes": self.notes,
        }


def _rms(sse: float, n: int) -> float:
    return float(np.sqrt(sse / n))


def global_stage(ev: Evaluator, u0: np.ndarray, s: FitSettings,
                 on_generation: Callable[[int, float], None] | None = None) -> tuple[np.ndarray, dict]:
    """CMA-ES from u0 within [0, 1]^n; the best point seen (u0 if nothing beat it).

    With one free parameter (CMA-ES needs two) it is a scan of ``budget`` evenly spaced values.
    """
    import cma

    if len(u0) == 1:
        return _scan(ev, u0, s)
    f0 = float(ev.sse([u0])[0])
    scale = f0 if f0 > 0 else 1.0  # CMA sees SSE / SSE(start): its tolerances become relative
    opts = {"bounds": [0.0, 1.0], "maxfevals": s.budget, "seed": s.seed, "verbose": -9}
    if s.popsize:
        opts["popsize"] = s.popsize
    state = np.random.get_state()  # cma seeds numpy's global generator: leave it as it was
    try:
        es = cma.CMAEvolutionStrategy(list(u0), s.sigma0, opts)
        generation = 0
        while not es.stop():
            X = es.ask()
            f = ev.sse([np.asarray(x) for x in X]) / scale
            es.tell(X, f.tolist())
            generation += 1
            if on_generation is not None:
                on_generation(generation, scale * float(es.result.fbest))
        best, fbest, evals = np.asarray(es.result.xbest), scale * float(es.result.fbest), int(es.result.evaluations)
        stop = ", ".join(f"{k}={v}" for k, v in es.stop().items())
    finally:
        np.random.set_state(state)
    if not fbest < f0:
        best, fbest = np.asarray(u0, dtype=np.float64), f0
    n = ev.n_residuals
    return np.clip(best, 0.0, 1.0), {"stage": "global", "method": "CMA-ES (cma)", "evaluations": evals,
                                     "generations": generation, "rms_before": _rms(f0, n),
                                     "rms_after": _rms(fbest, n), "stop": stop}


def _scan(ev: Evaluator, u0: np.ndarray, s: FitSettings) -> tuple[np.ndarray, dict]:
    points = [np.asarray(u0, dtype=np.float64)] + [np.array([x]) for x in np.linspace(0.0, 1.0, max(s.budget, 2))]
    f = ev.sse(points)
    k = int(np.argmin(f))
    n = ev.n_residuals
    return points[k], {"stage": "global", "method": "scan (one free parameter)", "evaluations": len(points) - 1,
                       "generations": 1, "rms_before": _rms(float(f[0]), n), "rms_after": _rms(float(f[k]), n),
                       "stop": "budget"}


def local_stage(ev: Evaluator, u0: np.ndarray, s: FitSettings) -> tuple[np.ndarray, dict]:
    """Trust-region least squares from u0 with batched central-difference Jacobians.

    The discrete events of the engine make the trust region collapse early now and then: the
    solver is restarted from its solution while that lowers the sum of squares by more than
    :data:`RESTART_GAIN` (at most :data:`MAX_RESTARTS` times), within ``s.max_nfev`` in all.
    """
    def fun(u):
        return ev.evaluate([u])[0].residuals

    def jac(u):
        J, _ = ev.model_jacobian(u, s.diff_step)
        return ev.centred(J)

    u = np.asarray(u0, dtype=np.float64)
    f0 = f = ev.evaluate([u])[0].sse
    nfev = njev = runs = 0
    res = None
    while runs <= MAX_RESTARTS and nfev < s.max_nfev:
        res = least_squares(fun, u, jac=jac, bounds=(0.0, 1.0), method="trf", max_nfev=s.max_nfev - nfev,
                            x_scale=1.0)
        runs += 1
        nfev, njev = nfev + int(res.nfev), njev + int(res.njev or 0)
        u_new = np.clip(res.x, 0.0, 1.0)
        f_new = ev.evaluate([u_new])[0].sse
        if not f_new < f:
            break
        gain = (f - f_new) / f if f > 0 else 0.0
        u, f = u_new, f_new
        if gain <= RESTART_GAIN:
            break
    n = ev.n_residuals
    return u, {"stage": "local", "method": "least_squares (trf, central-difference Jacobian)",
               "evaluations": nfev, "jacobians": njev, "runs": runs, "rms_before": _rms(f0, n),
               "rms_after": _rms(f, n), "status": int(res.status), "message": str(res.message)}


def uncertainty(ev: Evaluator, u: np.ndarray, s: FitSettings) -> tuple[Covariance, np.ndarray]:
    """Covariance of (fitted values, offsets) at u, and the offsets there; a value whose standard
    error exceeds UNDETERMINED_WIDTHS times the width of its bounds, or whose bounds both leave
    the misfit within DETERMINED_CHI2 noise variances of the solution's (the runs simulated
    with it at each bound: 2 points a value, :func:`.fit_uncertainty.flat_within_bounds`), is
    marked not determined (infinite)."""
    Jm, centre = ev.model_jacobian(u, s.diff_step)
    n = ev.box.n
    blocks = [Jm]
    if ev.fit_offsets:
        E = np.zeros((ev.n_residuals, len(ev.slices)))
        for k, sl in enumerate(ev.slices):
            E[sl, k] = 1.0
        blocks.append(E)
    cov = covariance(np.hstack(blocks), centre.residuals, ev.slices)
    T = np.eye(cov.ar1.shape[0])
    T[:n, :n] = ev.box.value_jacobian(u)  # unit box -> values (triangular: ordered pairs)
    lost = ~np.isfinite(np.diag(cov.ar1))
    lost = lost | (np.abs(T[:, lost]) > 0).any(axis=1)  # a value depending on an unidentified one

    def to_values(C: np.ndarray) -> np.ndarray:
        out = T @ np.where(np.isfinite(C), C, 0.0) @ T.T
        out[lost, lost] = np.inf
        return out

    cov = Covariance(to_values(cov.ar1), to_values(cov.white), cov.rho, cov.sigma, cov.dof, cov.rank_deficient)
    widths = [f.hi - f.lo for f in ev.box.free] + [np.inf] * (cov.ar1.shape[0] - n)  # offsets: unbounded
    cov = mark_undetermined(cov, widths)
    ends = [np.where(np.arange(n) == i, end, u) for i in range(n) for end in (0.0, 1.0)]  # the unit box's bounds
    flat = flat_within_bounds(ev.sse(ends).reshape(n, 2), centre.sse, cov)
    return marked(cov, np.concatenate([flat, np.zeros(cov.ar1.shape[0] - n, dtype=bool)])), centre.offsets


def fit_actuator(runs: Sequence[BenchRun], box: FreeBox, pool, settings: FitSettings = FitSettings(),
                 on_sim: Callable[[int], None] | None = None) -> ActuatorFit:
    """Fit the free parameters of ``box`` to ``runs`` (global stage, then local).

    Raises
    ------
    FitError
        If a run cannot be simulated at the solution (the message names it).
    """
    t0 = time.perf_counter()
    ev = Evaluator(runs, box, pool, settings.fit_offsets, settings.dt_s, on_sim)
    u_start = box.start()
    start_eval = ev.evaluate([u_start])[0]
    stages = []
    u = u_start
    if settings.budget > 0:
        u, log = global_stage(ev, u, settings)
        stages.append(log)
    u, log = local_stage(ev, u, settings)
    stages.append(log)
    final = ev.evaluate([u])[0]
    if final.failures:
        raise FitError(f"the best set found cannot simulate every run: {final.failures[0]}")
    cov, offsets = uncertainty(ev, u, settings)
    names, files = box.names, [r.file for r in runs]
    se, se_w = cov.stderr, cov.stderr_white
    notes = []
    if cov.rank_deficient:
        labels = list(names) + ([f"the offset of {f}" for f in files] if settings.fit_offsets else [])
        lost = [k for k, bad in zip(labels, cov.undetermined) if bad]
        notes.append(f"not determined by these runs: {', '.join(lost)} (a singular Jacobian, a standard error "
                     f"more than {UNDETERMINED_WIDTHS:g} times the width of the bounds, or a misfit within "
                     f"{DETERMINED_CHI2:g} noise variance of the solution's at both bounds): standard error infinite "
                     "(null in the report)")
    if start_eval.failures:
        notes.append(f"the start set failed on a run ({start_eval.failures[0]})")
    if log["status"] == 0 or log["evaluations"] >= settings.max_nfev:
        notes.append(f"the local fit stopped at its limit of {settings.max_nfev} evaluations (--max-nfev), not at a "
                     "minimum: the values and their errors may still change with more")
    n = box.n
    return ActuatorFit(
        free=box.free, params=box.params(u), start=box.values(u_start), values=box.values(u),
        stderr=dict(zip(names, se[:n].tolist())), stderr_white=dict(zip(names, se_w[:n].tolist())),
        correlation=cov.correlation()[:n, :n].tolist(),
        offsets=dict(zip(files, offsets.tolist())),
        offset_stderr=dict(zip(files, se[n:].tolist())) if settings.fit_offsets else {f: None for f in files},
        rho=dict(zip(files, cov.rho.tolist())), rms_start=_rms(start_eval.sse, ev.n_residuals),
        rms=_rms(final.sse, ev.n_residuals), at_bounds=box.at_bounds(u), stages=stages,
        n_simulations=ev.n_sims, wall_s=time.perf_counter() - t0, rank_deficient=cov.rank_deficient,
        settings=settings, notes=notes)
