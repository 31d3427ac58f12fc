"""Fit of one phase (heating or cooling) of the joint-level identification (:mod:`.joint_fit`).

The search strategy: coarse scans of the fit vector, then trust-region least squares with 1 %
secant steps (restarted while it improves), then standard errors from a 1 %-secant Jacobian in
log(value). The module docstring of :mod:`.joint_fit` explains why (the model is nonsmooth in
its parameters).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
from scipy.optimize import least_squares

from ..parameters import ParameterSet
from ..profiles import VoltageProgram
from .data import AngleCurve
from .fit_uncertainty import null_directions
from .joint_experiments import joint_set, program_text
from .joint_objective import PhaseObjective

PHASE_FIELDS = {
    "heating": ("h0_heating_W_m2K", "h2_heating_W_m2K3", "C_DF_heating_Nms"),
    "cooling": ("h0_cooling_W_m2K", "h2_cooling_W_m2K3", "C_DF_cooling_Nms"),
}
MSF_FIELD = "M_SF_Nm"
DIFF_STEP = 0.01  # 1 % relative finite-difference step
SCAN_FACTORS = np.geomspace(0.25, 4.0, 9)  # common factor on h0 and h2
COORD_FACTORS = (0.25, 0.5, 2.0, 4.0)  # each other fitted parameter
MAX_RUNS = 4  # least-squares runs (restarts from the previous solution)
RESTART_TOL = 1e-4  # restart while a run lowers the SSE by more than this fraction
H_CORR_WARN = 0.99  # |corr(h0, h2)| above this: warn that they are not separately identifiable
REL_SE_WARN = 0.10  # relative standard error above this: warn


@dataclass
class PhaseFit:
    """Fit of one phase (heating or cooling) to its curves."""

    phase: str
    fields: tuple[str, ...]
    start: dict[str, float]
    values: dict[str, float]
    stderr: dict[str, float]
    rel_stderr: dict[str, float]
    correlation: list[list[float]]
    rms_deg: float
    rms_start_deg: float
    curves: list[dict]  # per curve: path, program, n_points, rms_deg
    nfev: int
    wall_s: float
    scan_factor: float
    success: bool
    message: str
    warnings: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in ("phase", "fields", "start", "values", "stderr", "rel_stderr",
                                              "correlation", "rms_deg", "rms_start_deg", "curves", "nfev",
                                              "wall_s", "scan_factor", "success", "message", "warnings")}


def fit_phase(phase: str, experiments: Sequence[tuple[AngleCurve, VoltageProgram]], base: ParameterSet,
              fit_msf: bool = False, scan: bool = True,
              on_eval: Callable[[int], None] | None = None, max_nfev: int = 40) -> PhaseFit:
    """Fit the ``phase`` coefficients (plus M_SF if ``fit_msf``) to one or more curves of that
    phase together, starting from ``base``."""
    fields, start = _phase_start(phase, experiments, base, fit_msf)
    t0 = time.perf_counter()
    obj = PhaseObjective(base, phase, fields, start, experiments, on_eval)
    z0 = np.zeros(len(fields))
    rms_start = math.sqrt(obj.sse(z0) / obj.n_points)
    best = rms_start**2 * obj.n_points
    best_k = 1.0
    if scan:
        z0, best = _coarse_scans(obj, z0, best)
        best_k = math.exp(z0[0])
    z, runs, success, message = _local_fit(obj, z0, best, max_nfev)
    values = obj.values(z)
    r, sd, corr = _log_uncertainty(obj, values)
    return PhaseFit(
        phase=phase, fields=fields, start=start, values=values,
        stderr={f: float(values[f] * sd[i]) for i, f in enumerate(fields)},
        rel_stderr={f: float(sd[i]) for i, f in enumerate(fields)},
        correlation=[[float(c) for c in row] for row in corr],
        rms_deg=math.sqrt(float(r @ r) / r.size), rms_start_deg=rms_start,
        curves=_per_curve(experiments, r), nfev=obj.nfev, wall_s=time.perf_counter() - t0,
        scan_factor=best_k, success=success, message=f"{message} ({runs} least-squares run(s))",
        warnings=(_identifiability_warnings(phase, fields, corr, sd) + _bound_warnings(phase, obj, z, values)
                  + _stability_warnings(phase, obj.params(z))),
    )


#: the share of RK4's stable step against the damping beyond which a fitted set is at the wall
#: (:func:`_stability_warnings`)
NEAR_STABILITY = 0.9


def _stability_warnings(phase: str, p: ParameterSet) -> list[str]:
    """A fitted damping near what RK4 holds at the fit's step (:data:`.joint_experiments.FIT_DT_S`):
    candidates beyond it blew up and were scored as misses, a wall the fit can stop at. Found by
    review: curves made with C_DF_cooling 0.2 were fitted to 0.1355 +- 9e-8, the wall at 1 ms."""
    from ..engine.numerics import damping_rate_per_s, damping_step_limit
    from .joint_experiments import FIT_DT_S, FIT_METHOD

    limit = damping_step_limit(p, FIT_METHOD)
    if limit is None or FIT_DT_S < NEAR_STABILITY * limit:
        return []
    return [f"{phase}: the fitted damping (C_DF / I = {damping_rate_per_s(p):.4g} 1/s) is at "
            f"{FIT_DT_S / limit:.0%} of what {FIT_METHOD} holds at the fit's {FIT_DT_S * 1e3:g} ms step: candidates "
            "beyond it blew up and were scored as misses, so the value may be that limit's, not the curves'"]


#: a fitted log-value this close to an end of its search range is at the bound
AT_BOUND = 1e-6


def _bound_warnings(phase: str, obj: PhaseObjective, z: np.ndarray, values: dict) -> list[str]:
    """A field the fit stopped at an end of its search range: the data push it further, so its
    value is the bound's and its standard error does not describe it."""
    out = []
    for i, f in enumerate(obj.fields):
        lo, hi = obj.bounds[i]
        end = "upper" if z[i] >= hi - AT_BOUND else "lower" if z[i] <= lo + AT_BOUND else None
        if end is not None:
            out.append(f"{phase}: {f} = {values[f]:.6g} is at the {end} bound of its search range: the curves "
                       "push it further, so the value is the bound's and its standard error does not apply")
    return out


def _phase_start(phase: str, experiments: Sequence[tuple[AngleCurve, VoltageProgram]], base: ParameterSet,
                 fit_msf: bool) -> tuple[tuple[str, ...], dict[str, float]]:
    """The fitted fields of ``phase`` and their starting values from ``base``.

    Parameters
    ----------
    phase : str
        ``"heating"`` or ``"cooling"``.
    experiments : sequence of (AngleCurve, VoltageProgram)
        The curves to fit (at least one).
    base : ParameterSet
        The starting set.
    fit_msf : bool
        Whether M_SF is fitted too.

    Returns
    -------
    fields : tuple of str
        h0, h2 and C_DF of the phase (and M_SF).
    start : dict
        Their values in ``base``.

    Raises
    ------
    ValueError
        For an unknown phase, no curve, or a start that is not positive (h2 may be 0).
    """
    if phase not in PHASE_FIELDS:
        raise ValueError(f"phase = {phase!r} is not one of {', '.join(PHASE_FIELDS)}")
    if not experiments:
        raise ValueError(f"no {phase} curve to fit")
    joint_set(base)
    fields = PHASE_FIELDS[phase] + ((MSF_FIELD,) if fit_msf else ())
    start = {}
    for f in fields:
        v = float(getattr(base, f))
        if not (v > 0 or (f == fields[1] and v == 0)):
            raise ValueError(f"{f} = {v} in the starting set: the fit works on log(value) and needs a "
                             f"positive start")
        start[f] = v
    return fields, start


def _coarse_scans(obj: PhaseObjective, z0: np.ndarray, best: float) -> tuple[np.ndarray, float]:
    """Step 1: greedy scans from ``z0`` (sum of squares ``best``).

    A common factor on h0 and h2 (the timing), then each other parameter on its own (q, C_DF,
    M_SF; a too-large M_SF can keep the joint from ever moving), then again on h if anything
    else moved. With M_SF fitted, M_SF and h are first scanned together (together they decide
    when the joint breaks away).

    Parameters
    ----------
    obj : PhaseObjective
        The objective.
    z0 : ndarray
        The starting fit vector.
    best : float
        Its sum of squared residuals [deg^2].

    Returns
    -------
    z : ndarray
        The best fit vector found.
    best : float
        Its sum of squared residuals [deg^2].
    """
    fields = obj.fields
    if MSF_FIELD in fields:
        i_msf = fields.index(MSF_FIELD)
        for m in COORD_FACTORS:
            zz = z0.copy()
            zz[i_msf] += math.log(m)
            zz, b = _scan(obj, zz, obj.sse(zz), 0, SCAN_FACTORS)
            if b < best:
                z0, best = zz, b
    z0, best = _scan(obj, z0, best, 0, SCAN_FACTORS)
    moved = False
    for i in range(1, len(fields)):
        z0, b = _scan(obj, z0, best, i, COORD_FACTORS)
        moved = moved or b < best
        best = b
    if moved:
        z0, best = _scan(obj, z0, best, 0, SCAN_FACTORS)
    return z0, best


def _scan(obj: PhaseObjective, z: np.ndarray, best: float, i: int, factors) -> tuple[np.ndarray, float]:
    """Try ``z[i] + log(factor)`` for each factor; keep the best (greedy)."""
    z_best = z.copy()
    for k in factors:
        if k == 1.0:
            continue
        zz = z.copy()
        zz[i] = z[i] + math.log(k)
        lo, hi = obj.bounds[i]
        if not lo <= zz[i] <= hi:
            continue
        s = obj.sse(zz)
        if s < best:
            z_best, best = zz, s
    return z_best, best


def _local_fit(obj: PhaseObjective, z0: np.ndarray, sse: float,
               max_nfev: int) -> tuple[np.ndarray, int, bool, str]:
    """Step 2: trust-region least squares from ``z0``, central differences with 1 % steps.

    Near the optimum the jitter of the model makes the trust region collapse early, so the fit
    restarts from its solution (a fresh trust region) until a run no longer improves, at most
    :data:`MAX_RUNS` runs.

    Parameters
    ----------
    obj : PhaseObjective
        The objective.
    z0 : ndarray
        The start (clipped just inside the bounds).
    sse : float
        The sum of squared residuals [deg^2] at ``z0``.
    max_nfev : int
        Budget of each run (:func:`scipy.optimize.least_squares`).

    Returns
    -------
    z : ndarray
        The solution.
    runs : int
        The number of runs.
    success : bool
        The last run's success flag.
    message : str
        The last run's message.
    """
    lo = np.array([b[0] for b in obj.bounds])
    hi = np.array([b[1] for b in obj.bounds])
    z = np.clip(z0, lo + 1e-9, hi - 1e-9)
    success, message, runs = False, "", 0
    for runs in range(1, MAX_RUNS + 1):
        res = least_squares(obj.residuals, z, bounds=(lo, hi), method="trf", jac="3-point",
                            diff_step=DIFF_STEP, x_scale=1.0, xtol=1e-8, ftol=1e-10, gtol=1e-10,
                            max_nfev=max_nfev)
        new_sse = 2.0 * float(res.cost)
        step = float(np.max(np.abs(res.x - z)))
        if new_sse <= sse:
            z, improved = res.x, sse - new_sse
            sse = new_sse
        else:
            improved = 0.0
        success, message = bool(res.success), str(res.message)
        if improved <= RESTART_TOL * sse or step < 1e-4:
            break
    return z, runs, success, message


def _log_uncertainty(obj: PhaseObjective, values: dict[str, float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step 3: residuals, relative standard errors and correlation at the solution ``values``.

    The Jacobian is taken in log(value) with central 1 % steps (secants across the jumps);
    ``cov = s^2 (J^T J)^-1`` with ``s^2 = SSR / (N - p)``.

    Parameters
    ----------
    obj : PhaseObjective
        The objective.
    values : dict
        The fitted fields' values.

    Returns
    -------
    r : ndarray
        Residuals [deg] at ``values``.
    sd : ndarray
        Standard error of log(value) of each field (relative standard error).
    corr : ndarray
        Correlation matrix of the log(values) (0 where undefined).
    """
    r = obj.residuals_at(values)
    J = np.empty((r.size, len(obj.fields)))
    for i, f in enumerate(obj.fields):
        up, dn = dict(values), dict(values)
        up[f] = values[f] * (1 + DIFF_STEP)
        dn[f] = values[f] * (1 - DIFF_STEP)
        J[:, i] = (obj.residuals_at(up) - obj.residuals_at(dn)) / (2 * DIFF_STEP)
    dof = max(r.size - len(obj.fields), 1)
    s2 = float(r @ r) / dof
    A = J.T @ J
    cov = s2 * np.linalg.pinv(A)  # of log(value): relative
    # a field the curves do not see (its column of J zero, or in a direction J^T J does not see):
    # infinitely uncertain, not exact (pinv gives such a field a variance of 0)
    cov[null_directions(A), :] = np.inf
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    corr = np.where(np.isfinite(corr), corr, 0.0)
    return r, sd, corr


def _per_curve(experiments: Sequence[tuple[AngleCurve, VoltageProgram]], r: np.ndarray) -> list[dict]:
    """Per curve: ``path``, ``program``, ``n_points`` and ``rms_deg`` of its share of ``r``.

    Parameters
    ----------
    experiments : sequence of (AngleCurve, VoltageProgram)
        The fitted curves, in the order of ``r``.
    r : ndarray
        All residuals [deg], the curves' concatenated.

    Returns
    -------
    list of dict
        One entry per curve.
    """
    per_curve = []
    k = 0
    for curve, prog in experiments:
        rc = r[k:k + curve.t_s.size]
        k += curve.t_s.size
        per_curve.append({"path": curve.path, "program": program_text(prog), "n_points": int(rc.size),
                          "rms_deg": math.sqrt(float(rc @ rc) / rc.size)})
    return per_curve


def _identifiability_warnings(phase: str, fields: Sequence[str], corr: np.ndarray, sd: np.ndarray) -> list[str]:
    """Warnings for h0 and h2 not separately identifiable, and for weakly identified fields.

    Parameters
    ----------
    phase : str
        ``"heating"`` or ``"cooling"`` (names the advice: which curve to add).
    fields : sequence of str
        The fitted fields, h0 and h2 first.
    corr : ndarray
        Correlation matrix of the log(values).
    sd : ndarray
        Relative standard errors.

    Returns
    -------
    list of str
        Empty if the fit is well identified.
    """
    warnings = []
    advice = ("add a slower heating curve (a lower voltage)" if phase == "heating" else
              "add a cooling curve from a different peak temperature (another heating time)")
    if abs(float(corr[0, 1])) > H_CORR_WARN:
        warnings.append(f"{phase}: h0 and h2 are not separately identifiable from these curves (correlation "
                        f"{corr[0, 1]:+.4f}); their standard errors understate the uncertainty: {advice}")
    weak = [f for i, f in enumerate(fields) if not sd[i] < REL_SE_WARN]
    if weak:
        warnings.append(f"{phase}: weakly identified (relative standard error above "
                        f"{100 * REL_SE_WARN:.0f}%): {', '.join(weak)}: {advice}")
    return warnings
