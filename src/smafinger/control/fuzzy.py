"""Fuzzy PWM-PID: the PID gains of Eq. (12a) scheduled by fuzzy rules on the error and its rate.

The same group replaced the paper's fixed-gain PWM-PID by a fuzzy PWM-PID on this finger
(Ko, Martin, Gilardi, Haslam, Park, "Fuzzy PWM-PID control of cocontracting antagonistic shape
memory alloy muscle pairs in an artificial finger", Mechatronics 21(7):1190-1202, 2011). The
scheduler implemented here is the classic fuzzy gain scheduling of PID controllers of Zhao,
Tomizuka and Isaka (IEEE Trans. Syst. Man Cybern. 23(5):1392-1398, 1993), its rules and
membership functions as published there:

- inputs: the error e = q_F - q and its rate de/dt = -q' (piecewise-constant target), each
  scaled to [-1, 1] by ``e_span`` and ``de_span`` (clipped) and fuzzified into seven
  triangular sets NB, NM, NS, ZO, PS, PM, PB centred at -1, -2/3, ..., 1 (half-width 1/3);
- a rule (i, j) fires with mu_i(e) mu_j(de) (product) and gives:
  K'_P and K'_D, each "Small" or "Big" (tables :data:`KP_RULES`, :data:`KD_RULES`), with the
  output membership functions mu_S(x) = -ln(x) / 4 and mu_B(x) = -ln(1 - x) / 4, so that a rule
  of strength mu gives x = exp(-4 mu) (Small) or 1 - exp(-4 mu) (Big); and alpha, a singleton
  2, 3, 4 or 5 (table :data:`ALPHA_RULES`);
- defuzzification: the firing-weighted mean of each output; then
  K_P = K_P,min + (K_P,max - K_P,min) K'_P, K_D likewise, and K_I = K_P^2 / (alpha K_D)
  (ZTI's T_I = alpha T_D).

Large errors get a big K_P and a small K_D (move fast); near the target the rules lower K_P,
raise K_D and alpha (brake, integrate gently). The scheduled PID output is distributed to the
wires by the paper's phase selection (Sec. 2.6).
"""

import math
from typing import NamedTuple

import numpy as np

from ..jit import njit
from .pid import pid_output

#: fuzzy sets of each input, in order (rows: e, columns: de/dt)
SETS = ("NB", "NM", "NS", "ZO", "PS", "PM", "PB")
#: ZTI 1993: K'_P rules (B: Big, S: Small); row e NB..PB, column de NB..PB
KP_RULES = ("BBBBBBB", "SBBBBBS", "SSBBBSS", "SSSBSSS", "SSBBBSS", "SBBBBBS", "BBBBBBB")
#: ZTI 1993: K'_D rules
KD_RULES = ("SSSSSSS", "BBSSSBB", "BBBSBBB", "BBBBBBB", "BBBSBBB", "BBSSSBB", "SSSSSSS")
#: ZTI 1993: alpha rules (T_I = alpha T_D)
ALPHA_RULES = ("2222222", "3322233", "4332334", "5433345", "4332334", "3322233", "2222222")

_KP_BIG = np.array([[c == "B" for c in row] for row in KP_RULES])
_KD_BIG = np.array([[c == "B" for c in row] for row in KD_RULES])
_ALPHA = np.array([[float(c) for c in row] for row in ALPHA_RULES])
_CENTRES = np.linspace(-1.0, 1.0, len(SETS))
_HALF_WIDTH = 2.0 / (len(SETS) - 1)


class FuzzyPID(NamedTuple):
    """Fuzzy gain-scheduled PWM-PID (gains in DC% per SI unit of q: rad or m)."""

    K_P_min: float
    K_P_max: float
    K_V_min: float  #: derivative gain range [% s / q]
    K_V_max: float
    e_span: float  #: error that maps to the outer sets [q]
    de_span: float  #: error rate that maps to the outer sets [q/s]


class Gains(NamedTuple):
    K_P: float
    K_V: float
    K_I: float


@njit(cache=True, forceinline=True)
def membership(x, k):
    """Membership of the scaled input x in set k (triangular; the outer sets saturate)."""
    c = _CENTRES[k]
    if (k == 0 and x <= c) or (k == len(_CENTRES) - 1 and x >= c):
        return 1.0
    return max(0.0, 1.0 - abs(x - c) / _HALF_WIDTH)


@njit(cache=True)
def scheduled_gains(ctrl, e, de):
    """:class:`Gains` at error e and error rate de (ZTI 1993: rule firing, weighted means)."""
    xe = min(max(e / ctrl.e_span, -1.0), 1.0)
    xd = min(max(de / ctrl.de_span, -1.0), 1.0)
    w_sum = 0.0
    kp = 0.0
    kd = 0.0
    alpha = 0.0
    for i in range(len(_CENTRES)):
        mi = membership(xe, i)
        if mi == 0.0:
            continue
        for j in range(len(_CENTRES)):
            mu = mi * membership(xd, j)
            if mu == 0.0:
                continue
            small = np.exp(-4.0 * mu)  # mu_S(x) = mu  <=>  x = exp(-4 mu)
            kp += mu * (1.0 - small if _KP_BIG[i, j] else small)
            kd += mu * (1.0 - small if _KD_BIG[i, j] else small)
            alpha += mu * _ALPHA[i, j]
            w_sum += mu
    if w_sum == 0.0:  # no rule fires (a NaN error): NaN gains, as compiled code's 0/0, in plain Python too
        return Gains(math.nan, math.nan, math.nan)
    kp /= w_sum
    kd /= w_sum
    alpha /= w_sum
    K_P = ctrl.K_P_min + (ctrl.K_P_max - ctrl.K_P_min) * kp
    K_V = ctrl.K_V_min + (ctrl.K_V_max - ctrl.K_V_min) * kd
    return Gains(K_P, K_V, K_P * K_P / (alpha * K_V) if K_V > 0.0 else 0.0)


@njit(cache=True, forceinline=True)
def fuzzy_output(ctrl, e, de, integral):
    """DC% of the scheduled PID (Eq. 12a with the gains of :func:`scheduled_gains`)."""
    g = scheduled_gains(ctrl, e, de)
    return pid_output(e, de, integral, g.K_P, g.K_V, g.K_I)
