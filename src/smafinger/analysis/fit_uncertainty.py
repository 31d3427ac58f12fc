"""Uncertainties of a least-squares fit whose residuals are autocorrelated.

Residuals of a time series fit are rarely independent: a position sampled at 100 Hz carries
the sensor's noise, but also any systematic misfit of the model, which is smooth in time.
The usual covariance s^2 (J^T J)^-1 then understates the uncertainty.

:func:`covariance` models each run's residuals as a stationary AR(1) process, with its own
variance s_k^2 and lag-1 autocorrelation rho_k (estimated from the residuals), so that
cov(r_i, r_j) = s_k^2 rho_k^|i-j| within run k and 0 across runs. The estimate of the
ordinary least-squares fit then has the *sandwich* covariance

    C = (J^T J)^-1 (sum_k J_k^T S_k J_k) (J^T J)^-1,    (S_k)_ij = s_k^2 rho_k^|i-j|

(the product S_k J_k is two first-order recursive filters, forward and backward, so no
N x N matrix is formed). With rho_k = 0 and one common variance it is s^2 (J^T J)^-1, which
is also returned (``white``). For white noise rho is near 0 and both agree; a systematic
misfit shows as rho near 1 and widens C by up to sqrt((1 + rho) / (1 - rho)) in standard error.

A quantity the data do not determine gets an infinite variance: one in a direction J^T J does
not see (:func:`null_directions`), and, where the quantities have bounds, one whose standard
error exceeds :data:`UNDETERMINED_WIDTHS` times the width of its bounds (:func:`mark_undetermined`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.signal import lfilter

#: |rho| is capped here: beyond, the AR(1) model's variance of a mean diverges
RHO_MAX = 0.995


def lag1_autocorrelation(r: np.ndarray) -> float:
    """sum r_t r_(t-1) / sum r_t^2, capped to [-RHO_MAX, RHO_MAX] (0 for a zero residual)."""
    r = np.asarray(r, dtype=np.float64)
    den = float(r @ r)
    if r.size < 2 or den == 0.0:
        return 0.0
    return float(np.clip((r[1:] @ r[:-1]) / den, -RHO_MAX, RHO_MAX))


def ar1_times(X: np.ndarray, rho: float) -> np.ndarray:
    """T X with T_ij = rho^|i-j| (columns of X filtered forward and backward)."""
    X = np.asarray(X, dtype=np.float64)
    if rho == 0.0:
        return X.copy()
    fwd = lfilter([1.0], [1.0, -rho], X, axis=0)
    bwd = lfilter([1.0], [1.0, -rho], X[::-1], axis=0)[::-1]
    return fwd + bwd - X


@dataclass(frozen=True)
class Covariance:
    """Covariances of the fitted quantities (columns of the Jacobian).

    Attributes
    ----------
    ar1 : ndarray
        Sandwich covariance with AR(1) residuals per run (the one to use).
    white : ndarray
        s^2 (J^T J)^-1: independent residuals of one variance.
    rho, sigma : ndarray
        Lag-1 autocorrelation and standard deviation of each run's residuals.
    dof : int
        Residuals minus fitted quantities.
    rank_deficient : bool
        Some quantities are not determined: J^T J was singular (the other entries then come from
        a pseudo-inverse), or a standard error exceeded the width of the bounds
        (:func:`mark_undetermined`). Their variances are infinite (:attr:`undetermined`).
    """

    ar1: np.ndarray
    white: np.ndarray
    rho: np.ndarray
    sigma: np.ndarray
    dof: int
    rank_deficient: bool

    @property
    def undetermined(self) -> np.ndarray:
        """Which quantities are not determined (an infinite variance), bool each."""
        return ~np.isfinite(np.diag(self.ar1))

    @property
    def stderr(self) -> np.ndarray:
        return np.sqrt(np.maximum(np.diag(self.ar1), 0.0))

    @property
    def stderr_white(self) -> np.ndarray:
        return np.sqrt(np.maximum(np.diag(self.white), 0.0))

    def correlation(self) -> np.ndarray:
        s = self.stderr
        with np.errstate(invalid="ignore", divide="ignore"):
            c = self.ar1 / np.outer(s, s)
        return np.where(np.isfinite(c), c, 0.0)


def covariance(J: np.ndarray, residuals: np.ndarray, slices: Sequence[slice]) -> Covariance:
    """Covariances of a least-squares estimate from its Jacobian and residuals.

    Parameters
    ----------
    J : ndarray, shape (N, p)
        d(residuals)/d(fitted quantities) at the solution (every quantity fitted jointly,
        offsets included).
    residuals : ndarray, shape (N,)
    slices : sequence of slice
        The rows of each run (the AR(1) model is fitted per run).
    """
    J = np.asarray(J, dtype=np.float64)
    r = np.asarray(residuals, dtype=np.float64)
    n, p = J.shape
    dof = max(n - p, 1)
    A = J.T @ J
    unidentified = null_directions(A)
    rank_deficient = bool(unidentified.any())
    A_inv = np.linalg.pinv(A) if rank_deficient else np.linalg.inv(A)
    scale = n / dof  # the residuals' mean square underestimates the noise variance by dof / n
    white = (r @ r) / dof * A_inv
    rho = np.array([lag1_autocorrelation(r[sl]) for sl in slices])
    sigma = np.array([np.sqrt(scale * np.mean(r[sl] ** 2)) for sl in slices])
    meat = np.zeros((p, p))
    for sl, rk, sk in zip(slices, rho, sigma):
        Jk = J[sl]
        meat += sk**2 * (Jk.T @ ar1_times(Jk, rk))
    ar1 = 0.5 * (A_inv @ meat @ A_inv + (A_inv @ meat @ A_inv).T)
    for c in (ar1, white):
        c[unidentified, unidentified] = np.inf
    return Covariance(ar1, white, rho, sigma, dof, rank_deficient)


def null_directions(A: np.ndarray, rtol: float = 1e-10) -> np.ndarray:
    """Which quantities take part in a direction J^T J does not see (bool per column)."""
    scale = np.sqrt(np.maximum(np.diag(A), 0.0))
    zero = scale == 0.0
    S = A / np.outer(np.where(zero, 1.0, scale), np.where(zero, 1.0, scale))
    w, V = np.linalg.eigh(S)
    null = V[:, w <= rtol * max(float(w.max()), 0.0)] if w.size else V[:, :0]
    return zero | (np.abs(null) > 1e-6).any(axis=1)


#: a standard error this many times the width of its quantity's range: not determined by the
#: data (:func:`mark_undetermined`; not 1: a user's bounds narrower than a well-determined
#: quantity's standard error said "not determined", found by review)
UNDETERMINED_WIDTHS = 10.0


def mark_undetermined(cov: Covariance, widths: np.ndarray) -> Covariance:
    """``cov`` with every quantity whose standard error exceeds :data:`UNDETERMINED_WIDTHS`
    times the width of its allowed range marked not determined, as a null direction is: its variances infinite (both), and
    ``rank_deficient`` set.

    :func:`null_directions` scales every column to unit size, so a quantity whose column is
    tiny but not zero (a temperature band a run barely reaches) passes as identified, with a
    finite standard error billions of times its range. Data that leave a quantity anywhere in
    its bounds, and beyond, do not determine it.

    Parameters
    ----------
    cov : Covariance
        In the units of ``widths``.
    widths : array_like
        The width of each quantity's range (hi - lo; ``inf`` for an unbounded one, such as an
        offset).
    """
    widths = np.asarray(widths, dtype=np.float64)
    return marked(cov, ~(cov.stderr <= UNDETERMINED_WIDTHS * widths))  # an infinite variance stays marked


def marked(cov: Covariance, which: np.ndarray) -> Covariance:
    """``cov`` with the quantities flagged in ``which`` (bool each) not determined: their
    variances infinite (both) and ``rank_deficient`` set."""
    which = np.asarray(which, dtype=bool)
    if not which.any():
        return cov
    ar1, white = cov.ar1.copy(), cov.white.copy()
    for c in (ar1, white):
        c[which, which] = np.inf
    return Covariance(ar1, white, cov.rho, cov.sigma, cov.dof, True)


#: a fitted value counts as determined within its bounds only if moving it to one of them, the
#: others held, raises the misfit by this many noise variances or more (chi^2 allowing for the
#: residuals' correlation: :func:`flat_within_bounds`)
DETERMINED_CHI2 = 1.0


def flat_within_bounds(sse_at_bounds: np.ndarray, sse: float, cov: Covariance) -> np.ndarray:
    """Which fitted values the data leave anywhere within their bounds (bool each): the misfit
    at each bound, the others held at the solution, is less than :data:`DETERMINED_CHI2` noise
    variances above the solution's. The linearised standard error can be finite and small there:
    a slider's mass that changes the runs' sum of squares by 0.44 noise variances between 5 and
    18 g was reported as 18 +- 6.5 g, the truth 3 g (found by review). Held, the others cannot
    make the profile flatter than this, only steeper, so this flags no value the data determine.

    Parameters
    ----------
    sse_at_bounds : ndarray, shape (n, 2)
        The sum of squared residuals with value i at its lower and its upper bound.
    sse : float
        At the solution.
    cov : Covariance
        At the solution; its first n quantities are the values (the noise variance is the
        residuals' mean square over ``dof``; the correlation of the residuals widens it by
        (stderr / stderr_white)^2 for each value).
    """
    n = sse_at_bounds.shape[0]
    with np.errstate(invalid="ignore", divide="ignore"):
        widening = (cov.stderr[:n] / cov.stderr_white[:n]) ** 2
        chi2 = (np.asarray(sse_at_bounds) - sse) / (sse / cov.dof) / np.maximum(widening, 1.0)[:, None]
    return np.isfinite(widening) & (np.nan_to_num(chi2, nan=np.inf) < DETERMINED_CHI2).all(axis=1)
