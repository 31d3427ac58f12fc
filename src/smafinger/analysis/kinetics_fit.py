"""Fit the cosine phase kinetics (Eqs. 9-10) to strain-temperature curves under constant load.

Model of a measured curve (row ``i`` at temperature ``T_i`` and stress ``sigma_i``)::

    strain_i = eps_R xi_i + sigma_i (1/D(xi_i) - 1/D_A) + offset,   D(xi) = D_A + xi (D_M - D_A)

``xi`` comes from the package's own kinetics (:func:`smafinger.model.kinetics.martensite_fraction`
and :func:`~smafinger.model.kinetics.branch_start`): the heating branch (Eq. 9) on the heating
half (rows up to the maximum temperature), the cooling branch (Eq. 10) on the cooling half, with
the simulator's minor-loop rule (the cooling branch's start value xi_A0 is re-solved at the
reversal so that xi is continuous). The first row starts fully martensitic (xi = 1), as after
cooling under load.

Offset: the zero of a measured strain curve is arbitrary (the sensor's zero; the loader shifts
each curve to a minimum of 0, and with noise that minimum lies a few noise levels below the
austenite level). The model's strain is measured from the austenite state at the same stress
(the elastic part ``sigma/D(xi) - sigma/D_A`` is 0 when xi = 0), and each curve gets one fitted
strain offset, the austenite level in the curve's zero. It is profiled out
(:func:`.kinetics_model.offset_residual`: for given kinetics the best offset is the curve's mean
of measured minus model), so the optimiser sees only the kinetics; the residuals' Jacobian is
that of the projected residuals, so the standard errors allow for the offsets, and they count
in ``N - p``. A curve only predicted (``--validate``, leave-one-out) gets its offset fitted the
same way, the one thing fitted to it. The absolute elastic strain is not observable (the
offsets absorb it); only ``1/D_M - 1/D_A`` is, so D_A is held at the base set's value and D_M is
fitted (``fit_moduli``).

Stress: by default each curve uses its mean measured stress (the load is a dead weight; the
row-to-row scatter of the measured stress, about +-5 MPa, is load-cell noise and would move the
transformation temperatures by about +-0.7 degC per row). ``stress="row"`` uses each row's value.

All curves are fitted together (so that the stress slopes c_A and c_M are identified) with
:func:`scipy.optimize.least_squares`; standard errors come from its Jacobian,
``cov = s^2 (J^T J)^-1`` with ``s^2 = SSR / (N - p)`` (p: the free kinetics entries and one
offset per curve). Neighbouring residuals of a filtered curve are strongly correlated, which
this formula ignores; ``stderr_ar1`` inflates it by ``sqrt((1 + r1) / (1 - r1))`` (r1: lag-1
autocorrelation of the residuals), a more honest size.

The pieces: :mod:`.kinetics_model` (the model strain and the fit vector), :mod:`.kinetics_guess`
(the starting values), :mod:`.kinetics_figure` (the figure); this module holds the fit. Their
public names are importable from here.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
from scipy.optimize import least_squares

from ..parameters import ParameterSet
from ..values import is_whole, one_or_many
from .data import StrainCurve
# the model, the starting values and the figure live in their own modules; their public names
# are re-exported here, where callers import them from
from .kinetics_figure import kinetics_figure  # noqa: F401
from .kinetics_guess import initial_guess
from .kinetics_model import (  # noqa: F401
    KINETIC_FIELDS, X_HI, X_LO, X_NAMES, X_SCALE, X_TO_FIELDS, KineticParams, curve_offset, curve_stress,
    model_curve, offset_residual, rms_strain, strain_path,
)

MIN_STRESS_SPAN_MPA = 5.0  # below this spread of the curves' mean stresses, c_A and c_M are held


@dataclass
class KineticsFit:
    """Result of :func:`fit_kinetics`."""

    params: KineticParams
    stderr: dict[str, float]
    stderr_ar1: dict[str, float]
    fitted: list[str]  # ParameterSet fields that were free
    rms: dict[str, float]  # per fitted curve path
    rms_all: float
    n_points: int
    nfev: int
    success: bool
    message: str
    stress: str
    initial: KineticParams
    correlation: dict[str, dict[str, float]] = field(default_factory=dict)
    at_bounds: list[str] = field(default_factory=list)  # fit-vector entries stuck at a bound
    notes: list[str] = field(default_factory=list)
    #: per fitted curve path: its strain offset, the austenite level in the curve's zero (the
    #: loader's: above the curve's minimum)
    offsets: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {
            "values": self.params.as_dict(),
            "stderr": self.stderr,
            "stderr_ar1": self.stderr_ar1,
            "fitted_fields": self.fitted,
            "rms_strain_all": self.rms_all,
            "n_points": self.n_points,
            "nfev": self.nfev,
            "success": self.success,
            "message": self.message,
            "stress_model": self.stress,
            "initial": self.initial.as_dict(),
            "correlation": self.correlation,
            "at_bounds": self.at_bounds,
            "notes": self.notes,
            "offsets": self.offsets,
        }


def _free_mask(fit_moduli: Sequence[str]) -> np.ndarray:
    fit_moduli = one_or_many(fit_moduli)  # "D_M" is one name, not D, _ and M (found by an API fuzz)
    free = np.ones(len(X_NAMES), dtype=bool)
    for name in ("D_M", "D_A"):
        if name not in fit_moduli:
            free[X_NAMES.index(name)] = False
    bad = set(fit_moduli) - {"D_M", "D_A"}
    if bad:
        raise ValueError(f"fit_moduli: unknown {', '.join(sorted(bad))} (use D_M and/or D_A)")
    return free


def fit_kinetics(curves: Sequence[StrainCurve], base: ParameterSet | KineticParams,
                 fit_moduli: Sequence[str] = ("D_M",), stress: str = "mean",
                 on_eval: Callable[[int], None] | None = None, max_nfev: int = 2000) -> KineticsFit:
    """Fit all curves together. ``base`` supplies the start of D_A/D_M and any held values.

    ``fit_moduli``: which of ``"D_M"``, ``"D_A"`` are free (only ``1/D_M - 1/D_A`` is observable
    with a fitted offset per curve, so freeing both is ill-posed; see the module docstring).
    ``on_eval(n)`` is called after every model evaluation (for progress display).
    """
    if not curves:
        raise ValueError("no curves to fit")
    if not (is_whole(max_nfev) and max_nfev >= 1):  # 1.5 was no budget at all (found by an API fuzz)
        raise ValueError(f"max_nfev = {max_nfev!r} must be a whole number >= 1")
    base_kp = base if isinstance(base, KineticParams) else KineticParams.from_set(base)
    init, free, notes = _fit_start(curves, base_kp, fit_moduli)
    x_all = np.clip(init._x(), X_LO + 1e-9, X_HI - 1e-9)
    residuals = _residual_function(curves, x_all, free, stress, on_eval)
    res = least_squares(residuals, x_all[free], bounds=(X_LO[free], X_HI[free]),
                        x_scale=X_SCALE[free], method="trf", max_nfev=max_nfev, xtol=1e-10,
                        ftol=1e-12, gtol=1e-10)
    kp = KineticParams._from_x(_full_x(x_all, free, res.x))
    r = res.fun
    cov = _field_covariance(r, res.jac, free, len(curves))
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    fitted = _fitted_fields(free)
    stderr = {f: float(se[i]) for i, f in enumerate(KINETIC_FIELDS) if f in fitted}
    infl = _ar1_inflation(r, curves)
    return KineticsFit(params=kp, stderr=stderr, stderr_ar1={f: v * infl for f, v in stderr.items()},
                       fitted=fitted, rms={c.path: rms_strain(kp, c, stress) for c in curves},
                       rms_all=float(np.sqrt(np.mean(r * r))), n_points=r.size, nfev=int(res.nfev),
                       success=bool(res.success), message=str(res.message), stress=stress, initial=init,
                       correlation=_correlation(cov, fitted), at_bounds=_at_bounds(res.x, free), notes=notes,
                       offsets={c.path: curve_offset(kp, c, stress) for c in curves})


def _fit_start(curves: Sequence[StrainCurve], base_kp: KineticParams,
               fit_moduli: Sequence[str]) -> tuple[KineticParams, np.ndarray, list[str]]:
    """The start of the fit and which entries of the fit vector are free.

    With all curves at one stress level the stress slopes, and D_M against eps_R, are not
    identifiable: c_A, c_M, D_A and D_M are then held at the base values (with a note).

    Parameters
    ----------
    curves : sequence of StrainCurve
        The curves to fit.
    base_kp : KineticParams
        The base values (start of D_A and D_M, held values).
    fit_moduli : sequence of str
        Which of ``"D_M"``, ``"D_A"`` are free.

    Returns
    -------
    init : KineticParams
        The starting values (:func:`.kinetics_guess.initial_guess`).
    free : ndarray of bool
        Per entry of the fit vector (:data:`.kinetics_model.X_NAMES`): free or held.
    notes : list of str
        What was held and why.
    """
    init = initial_guess(curves, base_kp)
    free = _free_mask(fit_moduli)
    levels = [c.stress_MPa_mean for c in curves]
    notes = []
    if max(levels) - min(levels) < MIN_STRESS_SPAN_MPA:
        for name in ("c_A", "c_M", "D_M", "D_A"):
            free[X_NAMES.index(name)] = False
        init = dataclasses.replace(init, c_A_Pa_per_C=base_kp.c_A_Pa_per_C, c_M_Pa_per_C=base_kp.c_M_Pa_per_C)
        notes.append(f"all curves at one stress level ({min(levels):.0f}-{max(levels):.0f} MPa): c_A, c_M, D_A and "
                     f"D_M are held at the base values (fit two or more stress levels to identify them)")
    return init, free, notes


def _full_x(x_all: np.ndarray, free: np.ndarray, xf: np.ndarray) -> np.ndarray:
    """The whole fit vector: ``x_all`` with its free entries replaced by ``xf``."""
    x = x_all.copy()
    x[free] = xf
    return x


def _residual_function(curves: Sequence[StrainCurve], x_all: np.ndarray, free: np.ndarray, stress: str,
                       on_eval: Callable[[int], None] | None) -> Callable[[np.ndarray], np.ndarray]:
    """The residuals (model + offset - measured strain, all curves concatenated, each curve's
    offset profiled out by :func:`.kinetics_model.offset_residual`) of the free entries.

    Parameters
    ----------
    curves : sequence of StrainCurve
        The fitted curves.
    x_all : ndarray
        The whole fit vector (held entries at their values).
    free : ndarray of bool
        Which entries are free.
    stress : str
        ``"mean"`` or ``"row"`` (:func:`.kinetics_model.curve_stress`).
    on_eval : callable or None
        Called with the number of evaluations so far after each one.

    Returns
    -------
    callable
        ``residuals(xf)`` of the free entries ``xf``.
    """
    stresses = [curve_stress(c, stress) for c in curves]
    T = [np.ascontiguousarray(c.T_C, dtype=float) for c in curves]
    bufs = [(np.empty(c.n), np.empty(c.n)) for c in curves]
    count = [0]

    def residuals(xf: np.ndarray) -> np.ndarray:
        kp = KineticParams._from_x(_full_x(x_all, free, xf))
        out = []
        for c, Tc, sig, (xi, eps) in zip(curves, T, stresses, bufs):
            strain_path(Tc, sig, int(c.split), kp.A_S0_C, kp.A_F0_C, kp.c_A_Pa_per_C, kp.M_S0_C,
                        kp.M_F0_C, kp.c_M_Pa_per_C, kp.eps_R, kp.D_A_Pa, kp.D_M_Pa, xi, eps)
            out.append(offset_residual(eps, c.strain)[0])
        count[0] += 1
        if on_eval is not None:
            on_eval(count[0])
        return np.concatenate(out)

    return residuals


def _field_covariance(r: np.ndarray, J: np.ndarray, free: np.ndarray, n_offsets: int) -> np.ndarray:
    """Covariance of the fields (:data:`KINETIC_FIELDS`, in field units) by the delta method.

    ``cov = s^2 (J^T J)^-1`` of the free entries of the fit vector, ``s^2 = SSR / (N - p)``,
    mapped to the fields by :data:`.kinetics_model.X_TO_FIELDS` (held entries: 0). ``J`` is the
    Jacobian of the residuals with the offsets profiled out, ``(I - P) J_full``; its
    ``(J^T J)^-1`` is the kinetics block of the full problem's (offsets as unknowns), so the
    offsets' uncertainty is included. p counts the free entries and the offsets.

    Parameters
    ----------
    r : ndarray
        Residuals at the solution.
    J : ndarray
        Their Jacobian in the free entries.
    free : ndarray of bool
        Which entries of the fit vector are free.
    n_offsets : int
        The number of profiled-out offsets (one per curve).

    Returns
    -------
    ndarray
        Covariance matrix, one row and column per field.
    """
    n, p = r.size, int(free.sum()) + n_offsets
    s2 = float(r @ r) / max(n - p, 1)
    cov_f = s2 * np.linalg.pinv(J.T @ J)
    cov_x = np.zeros((len(X_NAMES), len(X_NAMES)))
    cov_x[np.ix_(free, free)] = cov_f
    return X_TO_FIELDS @ cov_x @ X_TO_FIELDS.T


def _ar1_inflation(r: np.ndarray, curves: Sequence[StrainCurve]) -> float:
    """``sqrt((1 + r1) / (1 - r1))``, r1 the lag-1 autocorrelation of the residuals within each
    curve (clipped to [0, 0.99]).

    Parameters
    ----------
    r : ndarray
        Residuals, the curves' concatenated in order.
    curves : sequence of StrainCurve
        The fitted curves.

    Returns
    -------
    float
        The factor on the standard errors (1 for uncorrelated residuals).
    """
    num = den = 0.0
    k = 0
    for c in curves:
        rc = r[k:k + c.n]
        k += c.n
        num += float(rc[1:] @ rc[:-1])
        den += float(rc @ rc)
    r1 = min(max(num / den if den > 0 else 0.0, 0.0), 0.99)
    return math.sqrt((1 + r1) / (1 - r1))


def _fitted_fields(free: np.ndarray) -> list[str]:
    """The fields (:data:`KINETIC_FIELDS`) that depend on a free entry of the fit vector."""
    return [f for row, f in zip(X_TO_FIELDS, KINETIC_FIELDS) if np.any(row[free] != 0.0)]


def _correlation(cov: np.ndarray, fitted: Sequence[str]) -> dict[str, dict[str, float]]:
    """Correlation between the fitted fields, from their covariance ``cov`` (0 where undefined)."""
    corr = {}
    for i, fi in enumerate(KINETIC_FIELDS):
        if fi not in fitted:
            continue
        corr[fi] = {}
        for j, fj in enumerate(KINETIC_FIELDS):
            if fj in fitted:
                d = math.sqrt(cov[i, i] * cov[j, j])
                corr[fi][fj] = float(cov[i, j] / d) if d > 0 else 0.0
    return corr


def _at_bounds(xf: np.ndarray, free: np.ndarray) -> list[str]:
    """Names of the free fit-vector entries ``xf`` within 1e-6 of their range of a bound."""
    names = [n for n, fr in zip(X_NAMES, free) if fr]
    span = X_HI[free] - X_LO[free]
    return [n for n, xi, lo_, hi_, sp in zip(names, xf, X_LO[free], X_HI[free], span)
            if min(xi - lo_, hi_ - xi) < 1e-6 * sp]


def leave_one_out(curves: Sequence[StrainCurve], base: ParameterSet | KineticParams,
                  fit_moduli: Sequence[str] = ("D_M",), stress: str = "mean",
                  on_fit: Callable[[int, str], None] | None = None) -> list[dict]:
    """Fit on all curves but one, predict the one left out; one entry per curve (``path``,
    ``stress_MPa``, ``rms_strain`` of the prediction with the left-out curve's own strain offset
    fitted (:func:`.kinetics_model.rms_strain`: its zero is the sensor's), fitted ``values`` and
    ``params``).

    Needs at least three curves (two remain to identify the stress slopes); else ``[]``.
    ``on_fit(i, name)`` is called after each fit.
    """
    if len(curves) < 3:
        return []
    out = []
    for i, c in enumerate(curves):
        rest = [d for j, d in enumerate(curves) if j != i]
        f = fit_kinetics(rest, base, fit_moduli, stress)
        out.append({"path": c.path, "stress_MPa": c.stress_MPa_mean, "rms_strain": rms_strain(f.params, c, stress),
                    "values": f.params.as_dict(), "params": f.params})
        if on_fit is not None:
            on_fit(i, c.name)
    return out


def plausibility(kp: KineticParams) -> list[str]:
    """Physical plausibility problems of a fitted set (empty: plausible)."""
    problems = []
    if not kp.A_S0_C < kp.A_F0_C:
        problems.append(f"A_S0 = {kp.A_S0_C:.4g} degC is not below A_F0 = {kp.A_F0_C:.4g} degC")
    if not kp.M_F0_C < kp.M_S0_C:
        problems.append(f"M_F0 = {kp.M_F0_C:.4g} degC is not below M_S0 = {kp.M_S0_C:.4g} degC")
    if not kp.c_A_Pa_per_C > 0:
        problems.append(f"c_A = {kp.c_A_Pa_per_C:.4g} Pa/degC is not positive")
    if not kp.c_M_Pa_per_C > 0:
        problems.append(f"c_M = {kp.c_M_Pa_per_C:.4g} Pa/degC is not positive")
    return problems
