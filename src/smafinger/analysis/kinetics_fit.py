"""Fit the cosine phase kinetics (Eqs. 9-10) to strain-temperature curves under constant load.

Model of a measured curve (row ``i`` at temperature ``T_i`` and stress ``sigma_i``)::

    strain_i = eps_R xi_i + sigma_i (1/D(xi_i) - 1/D_A),   D(xi) = D_A + xi (D_M - D_A)

``xi`` comes from the package's own kinetics (:func:`smafinger.model.kinetics.martensite_fraction`
and :func:`~smafinger.model.kinetics.branch_start`): the heating branch (Eq. 9) on the heating
half (rows up to the maximum temperature), the cooling branch (Eq. 10) on the cooling half, with
the simulator's minor-loop rule (the cooling branch's start value xi_A0 is re-solved at the
reversal so that xi is continuous). The first row starts fully martensitic (xi = 1), as after
cooling under load.

Offset: the data is shifted so that its minimum (the austenite state) is 0, so the model's strain
is measured from the austenite state at the same stress: the elastic part is
``sigma/D(xi) - sigma/D_A``, which is 0 when xi = 0. No free offset is fitted. The absolute
elastic strain is therefore not observable; only ``1/D_M - 1/D_A`` is, so D_A is held at the
base set's value and D_M is fitted (``fit_moduli``).

Stress: by default each curve uses its mean measured stress (the load is a dead weight; the
row-to-row scatter of the measured stress, about +-5 MPa, is load-cell noise and would move the
transformation temperatures by about +-0.7 degC per row). ``stress="row"`` uses each row's value.

All curves are fitted together (so that the stress slopes c_A and c_M are identified) with
:func:`scipy.optimize.least_squares`; standard errors come from its Jacobian,
``cov = s^2 (J^T J)^-1`` with ``s^2 = SSR / (N - p)``. Neighbouring residuals of a filtered
curve are strongly correlated, which this formula ignores; ``stderr_ar1`` inflates it by
``sqrt((1 + r1) / (1 - r1))`` (r1: lag-1 autocorrelation of the residuals), a more honest size.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
from numba import njit
from scipy.optimize import least_squares

from ..model.kinetics import COOLING, HEATING, branch_start, martensite_fraction
from ..parameters import ParameterSet
from .data import StrainCurve

#: ParameterSet fields this fit produces
KINETIC_FIELDS = ("A_S0_C", "A_F0_C", "M_S0_C", "M_F0_C", "c_A_Pa_per_C", "c_M_Pa_per_C", "eps_R",
                  "D_A_Pa", "D_M_Pa")

# internal fit vector: A_S0, A_F0-A_S0, M_F0, M_S0-M_F0 [degC], c_A, c_M [MPa/degC], eps_R [%],
# D_M, D_A [GPa]
_X_NAMES = ("A_S0", "wA", "M_F0", "wM", "c_A", "c_M", "eps_R", "D_M", "D_A")
_X_LO = np.array([-100.0, 0.5, -100.0, 0.5, 0.5, 0.5, 0.01, 1.0, 1.0])
_X_HI = np.array([300.0, 200.0, 300.0, 200.0, 200.0, 200.0, 20.0, 1000.0, 1000.0])
MIN_STRESS_SPAN_MPA = 5.0  # below this spread of the curves' mean stresses, c_A and c_M are held
_X_SCALE = np.array([5.0, 5.0, 5.0, 5.0, 1.0, 1.0, 0.2, 5.0, 5.0])


@njit(cache=True)
def _strain_path(T, sigma, split, A_S0, A_F0, c_A, M_S0, M_F0, c_M, eps_R, D_A, D_M, xi_out, eps_out):
    """xi and model strain along one curve (heating branch to ``split``, then cooling)."""
    n = T.shape[0]
    xi = 1.0
    start = branch_start(HEATING, xi, T[0], sigma[0], A_S0, A_F0, c_A, M_S0, M_F0, c_M)
    branch = HEATING
    for i in range(n):
        if i == split + 1:
            # reversal: re-solve the cooling branch's start at the last heating state
            start = branch_start(COOLING, xi, T[split], sigma[split], A_S0, A_F0, c_A, M_S0, M_F0, c_M)
            branch = COOLING
        xi = martensite_fraction(branch, start, xi, T[i], sigma[i], A_S0, A_F0, c_A, M_S0, M_F0, c_M)[0]
        D = D_A + xi * (D_M - D_A)
        xi_out[i] = xi
        eps_out[i] = eps_R * xi + sigma[i] * (1.0 / D - 1.0 / D_A)


@dataclass(frozen=True)
class KineticParams:
    """The kinetics parameters in ParameterSet units (degC, Pa/degC, Pa)."""

    A_S0_C: float
    A_F0_C: float
    M_S0_C: float
    M_F0_C: float
    c_A_Pa_per_C: float
    c_M_Pa_per_C: float
    eps_R: float
    D_A_Pa: float
    D_M_Pa: float

    @classmethod
    def from_set(cls, p: ParameterSet) -> "KineticParams":
        return cls(**{k: float(getattr(p, k)) for k in KINETIC_FIELDS})

    def as_dict(self) -> dict[str, float]:
        return {k: float(getattr(self, k)) for k in KINETIC_FIELDS}

    def _x(self) -> np.ndarray:
        return np.array([self.A_S0_C, self.A_F0_C - self.A_S0_C, self.M_F0_C, self.M_S0_C - self.M_F0_C,
                         self.c_A_Pa_per_C / 1e6, self.c_M_Pa_per_C / 1e6, self.eps_R * 100.0,
                         self.D_M_Pa / 1e9, self.D_A_Pa / 1e9])

    @classmethod
    def _from_x(cls, x: np.ndarray) -> "KineticParams":
        return cls(A_S0_C=x[0], A_F0_C=x[0] + x[1], M_S0_C=x[2] + x[3], M_F0_C=x[2],
                   c_A_Pa_per_C=x[4] * 1e6, c_M_Pa_per_C=x[5] * 1e6, eps_R=x[6] / 100.0,
                   D_A_Pa=x[8] * 1e9, D_M_Pa=x[7] * 1e9)


# linear map from the fit vector x to the fields (in field units), for the delta method
_L = np.zeros((len(KINETIC_FIELDS), len(_X_NAMES)))
for _r, _entries in enumerate((((0, 1.0),), ((0, 1.0), (1, 1.0)), ((2, 1.0), (3, 1.0)), ((2, 1.0),),
                               ((4, 1e6),), ((5, 1e6),), ((6, 0.01),), ((8, 1e9),), ((7, 1e9),))):
    for _c, _v in _entries:
        _L[_r, _c] = _v


def curve_stress(curve: StrainCurve, stress: str = "mean") -> np.ndarray:
    """The stress [Pa] the model uses for each row (``"mean"`` or ``"row"``)."""
    if stress == "mean":
        return np.full(curve.n, float(np.mean(curve.stress_Pa)))
    if stress == "row":
        return np.asarray(curve.stress_Pa, dtype=float)
    raise ValueError(f"stress = {stress!r} is not one of mean, row")


def model_curve(kp: KineticParams, curve: StrainCurve, stress: str = "mean") -> tuple[np.ndarray, np.ndarray]:
    """(xi, strain) of the model along a measured curve."""
    sig = curve_stress(curve, stress)
    xi = np.empty(curve.n)
    eps = np.empty(curve.n)
    _strain_path(np.ascontiguousarray(curve.T_C, dtype=float), sig, int(curve.split), kp.A_S0_C, kp.A_F0_C,
                 kp.c_A_Pa_per_C, kp.M_S0_C, kp.M_F0_C, kp.c_M_Pa_per_C, kp.eps_R, kp.D_A_Pa, kp.D_M_Pa,
                 xi, eps)
    return xi, eps


def rms_strain(kp: KineticParams, curve: StrainCurve, stress: str = "mean") -> float:
    """RMS of (model - measured) strain over a curve."""
    r = model_curve(kp, curve, stress)[1] - curve.strain
    return float(np.sqrt(np.mean(r * r)))


# ---------------------------------------------------------------------------------------
# initial guess from the data
# ---------------------------------------------------------------------------------------
def _crossing(T: np.ndarray, y: np.ndarray, level: float) -> float:
    """Temperature at which the normalised strain y first falls (heating) below ``level``."""
    idx = np.flatnonzero(y <= level)
    if idx.size == 0:
        return float(T[-1])
    k = int(idx[0])
    if k == 0:
        return float(T[0])
    y0, y1 = y[k - 1], y[k]
    f = (y0 - level) / (y0 - y1) if y0 != y1 else 0.0
    return float(T[k - 1] + f * (T[k] - T[k - 1]))


def initial_guess(curves: Sequence[StrainCurve], base: KineticParams) -> KineticParams:
    """Transformation temperatures from where each half crosses 90% / 10% of its strain span,
    the stress slopes from a straight line through them across the curves."""
    # for 0.5 (cos(pi u) + 1): xi = 0.9 at u = 0.205, 0.1 at u = 0.795
    u90, u10 = math.acos(0.8) / math.pi, math.acos(-0.8) / math.pi
    rows = []
    for c in curves:
        lo, hi = float(np.min(c.strain)), float(np.max(c.strain))
        span = hi - lo if hi > lo else 1.0
        y = (c.strain - lo) / span
        h = slice(0, c.split + 1)
        t90, t10 = _crossing(c.T_C[h], y[h], 0.9), _crossing(c.T_C[h], y[h], 0.1)
        wA = max((t10 - t90) / (u10 - u90), 1.0)
        A_S = t90 - u90 * wA
        # cooling: follow the rows backwards from the coldest end (strain falls as T rises)
        Tc, yc = c.T_C[c.split:][::-1], y[c.split:][::-1]
        c90, c10 = _crossing(Tc, yc, 0.9), _crossing(Tc, yc, 0.1)
        wM = max((c10 - c90) / (u10 - u90), 1.0)
        M_F = c90 - u90 * wM
        rows.append((c.stress_MPa_mean, A_S, wA, M_F, wM, hi))
    a = np.array(rows)
    s = a[:, 0]
    c_A, c_M = base.c_A_Pa_per_C / 1e6, base.c_M_Pa_per_C / 1e6
    if len(curves) >= 2 and np.ptp(s) > 1.0:
        kA = np.polyfit(s, a[:, 1], 1)[0]
        kM = np.polyfit(s, a[:, 3], 1)[0]
        if kA > 1e-3:
            c_A = float(np.clip(1.0 / kA, 1.0, 100.0))
        if kM > 1e-3:
            c_M = float(np.clip(1.0 / kM, 1.0, 100.0))
    A_S0 = float(np.mean(a[:, 1] - s / c_A))
    M_F0 = float(np.mean(a[:, 3] - s / c_M))
    wA, wM = float(np.mean(a[:, 2])), float(np.mean(a[:, 4]))
    eps_R = float(np.clip(np.median(a[:, 5]), 1e-4, 0.19))
    return KineticParams(A_S0_C=A_S0, A_F0_C=A_S0 + wA, M_S0_C=M_F0 + wM, M_F0_C=M_F0,
                         c_A_Pa_per_C=c_A * 1e6, c_M_Pa_per_C=c_M * 1e6, eps_R=eps_R,
                         D_A_Pa=base.D_A_Pa, D_M_Pa=base.D_M_Pa)


# ---------------------------------------------------------------------------------------
# the fit
# ---------------------------------------------------------------------------------------
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
        }


def _free_mask(fit_moduli: Sequence[str]) -> np.ndarray:
    free = np.ones(len(_X_NAMES), dtype=bool)
    for name in ("D_M", "D_A"):
        if name not in fit_moduli:
            free[_X_NAMES.index(name)] = False
    bad = set(fit_moduli) - {"D_M", "D_A"}
    if bad:
        raise ValueError(f"fit_moduli: unknown {', '.join(sorted(bad))} (use D_M and/or D_A)")
    return free


def fit_kinetics(curves: Sequence[StrainCurve], base: ParameterSet | KineticParams,
                 fit_moduli: Sequence[str] = ("D_M",), stress: str = "mean",
                 on_eval: Callable[[int], None] | None = None, max_nfev: int = 2000) -> KineticsFit:
    """Fit all curves together. ``base`` supplies the start of D_A/D_M and any held values.

    ``fit_moduli``: which of ``"D_M"``, ``"D_A"`` are free (only ``1/D_M - 1/D_A`` is observable
    from min-shifted data, so freeing both is ill-posed; see the module docstring).
    ``on_eval(n)`` is called after every model evaluation (for progress display).
    """
    if not curves:
        raise ValueError("no curves to fit")
    base_kp = base if isinstance(base, KineticParams) else KineticParams.from_set(base)
    init = initial_guess(curves, base_kp)
    free = _free_mask(fit_moduli)
    levels = [c.stress_MPa_mean for c in curves]
    notes = []
    if max(levels) - min(levels) < MIN_STRESS_SPAN_MPA:
        # one stress level: the slopes, and D_M against eps_R, are not identifiable
        free[4] = free[5] = free[7] = free[8] = False
        init = dataclasses.replace(init, c_A_Pa_per_C=base_kp.c_A_Pa_per_C, c_M_Pa_per_C=base_kp.c_M_Pa_per_C)
        notes.append(f"all curves at one stress level ({min(levels):.0f}-{max(levels):.0f} MPa): c_A, c_M, D_A and "
                     f"D_M are held at the base values (fit two or more stress levels to identify them)")
    x_all = np.clip(init._x(), _X_LO + 1e-9, _X_HI - 1e-9)
    stresses = [curve_stress(c, stress) for c in curves]
    T = [np.ascontiguousarray(c.T_C, dtype=float) for c in curves]
    bufs = [(np.empty(c.n), np.empty(c.n)) for c in curves]
    count = [0]

    def full_x(xf: np.ndarray) -> np.ndarray:
        x = x_all.copy()
        x[free] = xf
        return x

    def residuals(xf: np.ndarray) -> np.ndarray:
        kp = KineticParams._from_x(full_x(xf))
        out = []
        for c, Tc, sig, (xi, eps) in zip(curves, T, stresses, bufs):
            _strain_path(Tc, sig, int(c.split), kp.A_S0_C, kp.A_F0_C, kp.c_A_Pa_per_C, kp.M_S0_C,
                         kp.M_F0_C, kp.c_M_Pa_per_C, kp.eps_R, kp.D_A_Pa, kp.D_M_Pa, xi, eps)
            out.append(eps - c.strain)
        count[0] += 1
        if on_eval is not None:
            on_eval(count[0])
        return np.concatenate(out)

    res = least_squares(residuals, x_all[free], bounds=(_X_LO[free], _X_HI[free]),
                        x_scale=_X_SCALE[free], method="trf", max_nfev=max_nfev, xtol=1e-10,
                        ftol=1e-12, gtol=1e-10)
    x = full_x(res.x)
    kp = KineticParams._from_x(x)
    r = res.fun
    n, p = r.size, int(free.sum())
    s2 = float(r @ r) / max(n - p, 1)
    J = res.jac
    cov_f = s2 * np.linalg.pinv(J.T @ J)
    cov_x = np.zeros((len(_X_NAMES), len(_X_NAMES)))
    cov_x[np.ix_(free, free)] = cov_f
    cov = _L @ cov_x @ _L.T
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    # lag-1 autocorrelation of the residuals, within each curve
    num = den = 0.0
    k = 0
    for c in curves:
        rc = r[k:k + c.n]
        k += c.n
        num += float(rc[1:] @ rc[:-1])
        den += float(rc @ rc)
    r1 = min(max(num / den if den > 0 else 0.0, 0.0), 0.99)
    infl = math.sqrt((1 + r1) / (1 - r1))
    field_free = dict(zip(KINETIC_FIELDS, (free[0], free[0] or free[1], free[2] or free[3], free[2], free[4],
                                           free[5], free[6], free[8], free[7])))
    fitted = [f for f in KINETIC_FIELDS if field_free[f]]
    stderr = {f: float(se[i]) for i, f in enumerate(KINETIC_FIELDS) if f in fitted}
    stderr_ar1 = {f: v * infl for f, v in stderr.items()}
    corr = {}
    for i, fi in enumerate(KINETIC_FIELDS):
        if fi not in fitted:
            continue
        corr[fi] = {}
        for j, fj in enumerate(KINETIC_FIELDS):
            if fj in fitted:
                d = math.sqrt(cov[i, i] * cov[j, j])
                corr[fi][fj] = float(cov[i, j] / d) if d > 0 else 0.0
    rms = {c.path: rms_strain(kp, c, stress) for c in curves}
    names = [n for n, fr in zip(_X_NAMES, free) if fr]
    span = _X_HI[free] - _X_LO[free]
    at_bounds = [n for n, xi, lo_, hi_, sp in zip(names, res.x, _X_LO[free], _X_HI[free], span)
                 if min(xi - lo_, hi_ - xi) < 1e-6 * sp]
    return KineticsFit(params=kp, stderr=stderr, stderr_ar1=stderr_ar1, fitted=fitted, rms=rms,
                       rms_all=float(np.sqrt(np.mean(r * r))), n_points=n, nfev=int(res.nfev),
                       success=bool(res.success), message=str(res.message), stress=stress, initial=init,
                       correlation=corr, at_bounds=at_bounds, notes=notes)


def leave_one_out(curves: Sequence[StrainCurve], base: ParameterSet | KineticParams,
                  fit_moduli: Sequence[str] = ("D_M",), stress: str = "mean",
                  on_fit: Callable[[int, str], None] | None = None) -> list[dict]:
    """Fit on all curves but one, predict the one left out; one entry per curve (``path``,
    ``stress_MPa``, ``rms_strain`` of the prediction, fitted ``values`` and ``params``).

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


# ---------------------------------------------------------------------------------------
# output
# ---------------------------------------------------------------------------------------
def kinetics_figure(fit: KineticsFit, fitted: Sequence[StrainCurve], validated: Sequence[StrainCurve] = (),
                    loo: Sequence[dict] = ()):
    """Data vs model (strain in % against temperature), one panel per curve.

    Solid: the fit on all fitted curves; dashed: the leave-one-out prediction of that curve.
    """
    from matplotlib.figure import Figure

    items = [(c, "fitted") for c in fitted] + [(c, "validated") for c in validated]
    items.sort(key=lambda it: it[0].stress_MPa_mean)
    loo_by = {d["path"]: d for d in loo}
    n = len(items)
    ncol = 2 if n > 1 else 1
    nrow = math.ceil(n / ncol)
    fig = Figure(figsize=(5.2 * ncol, 3.8 * nrow))
    axes = fig.subplots(nrow, ncol, squeeze=False, sharex=True, sharey=True)
    for ax, (c, role) in zip(axes.flat, items):
        h = slice(0, c.split + 1)
        k = slice(c.split, c.n)
        ax.plot(c.T_C[h], 100 * c.strain[h], ".", ms=2.5, color="tab:red", alpha=0.6, label="data, heating")
        ax.plot(c.T_C[k], 100 * c.strain[k], ".", ms=2.5, color="tab:blue", alpha=0.6, label="data, cooling")
        _, m = model_curve(fit.params, c, fit.stress)
        rms = rms_strain(fit.params, c, fit.stress)
        ax.plot(c.T_C[h], 100 * m[h], "-", color="darkred", lw=1.4, label="model (all fitted)")
        ax.plot(c.T_C[k], 100 * m[k], "-", color="navy", lw=1.4)
        title = f"{c.name}: {c.stress_MPa_mean:.0f} MPa, {role}, RMS {100 * rms:.3f}%"
        if c.path in loo_by:
            _, ml = model_curve(loo_by[c.path]["params"], c, fit.stress)
            ax.plot(c.T_C, 100 * ml, "--", color="k", lw=0.9, label="leave-one-out prediction")
            title += f"\nleft out: RMS {100 * loo_by[c.path]['rms_strain']:.3f}%"
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("temperature [degC]")
    for ax in axes[:, 0]:
        ax.set_ylabel("strain [%]")
    axes.flat[0].legend(fontsize=7, loc="lower left")
    p = fit.params
    fig.suptitle(f"cosine kinetics fit: A_S0 {p.A_S0_C:.1f}, A_F0 {p.A_F0_C:.1f}, M_S0 {p.M_S0_C:.1f}, "
                 f"M_F0 {p.M_F0_C:.1f} degC, c_A {p.c_A_Pa_per_C / 1e6:.2f}, c_M {p.c_M_Pa_per_C / 1e6:.2f} "
                 f"MPa/degC, eps_R {100 * p.eps_R:.2f}%", fontsize=9)
    fig.tight_layout()
    return fig
