"""Starting values of the kinetics fit (:mod:`.kinetics_fit`), read off the measured curves."""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from .data import StrainCurve
from .kinetics_model import KineticParams


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
    the stress slopes from a straight line through them across the curves; eps_R from the
    curves' strain spans (independent of each curve's zero, which the fit's offsets take)."""
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
        rows.append((c.stress_MPa_mean, A_S, wA, M_F, wM, hi - lo))
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
