"""Eqs. (1)-(6) in plain Python: dynamics, friction, tendon geometry (Eq. 11: :mod:`.thermal`).

Written from the paper (Gilardi et al., Robotica 28(5), 2010) and ``shared/MODEL-NOTES.md``,
not from ``smafinger.model``. SI units; temperatures in degC as in the paper.

Where the paper's formula only holds in the range its figures show, the general form is used
and the difference is stated: the moment arm of Eqs. (4b)/(5b) is an absolute value, and
Eq. (1b) gives it its sign by hand (F_U b_U - F_L b_L). Here the moment of a tendon force about
O is the cross product B x F itself (:func:`tendon_moment_arm`), which is the paper's signed
arm wherever the tendon passes on the side of O that Fig. 4 shows.
"""

from __future__ import annotations

import math


# --------------------------------------------------------------------------------------------
# Eqs. (3)-(6): the tendon of the joint
# --------------------------------------------------------------------------------------------
def attachment_point(r: float, alpha0: float, theta: float) -> tuple[float, float]:
    """Point B on the phalanx, Eq. (3): B = r (cos(alpha), sin(alpha)), alpha = theta + alpha0."""
    alpha = theta + alpha0
    return r * math.cos(alpha), r * math.sin(alpha)


def tendon_path(B, C, D, wrapped: bool) -> tuple[float, tuple[float, float]]:
    """(path length, point P the tendon leaves from) of one tendon, Eqs. (4a)/(5a).

    Straight (Configuration I for the upper tendon): C -> B, P = C. Wrapped over D
    (Configuration II): C -> D -> B, P = D; the fixed segment |CD| is part of the path so that
    the path is continuous at the switch (MODEL-NOTES).
    """
    P = D if wrapped else C
    free = math.hypot(B[0] - P[0], B[1] - P[1])
    fixed = math.hypot(D[0] - C[0], D[1] - C[1]) if wrapped else 0.0
    return fixed + free, P


def path_rate(B, P) -> float:
    """d(path)/d(theta) [m/rad]: d|PB|/dtheta = (B - P) . dB/dtheta / |PB|, dB/dtheta = (-Y_B, X_B)."""
    dx, dy = B[0] - P[0], B[1] - P[1]
    return (dx * (-B[1]) + dy * B[0]) / math.hypot(dx, dy)


def tendon_moment_arm(B, P) -> float:
    """Signed moment arm [m]: the moment about O of a unit tension pulling B toward P.

    (B x (P - B))_z / |PB| = (X_B Y_P - X_P Y_B) / |PB|: Eqs. (4b)/(5b) with the sign that
    Eq. (1b) writes by hand (+ for the upper tendon, - for the lower one in Fig. 4).
    """
    return (B[0] * P[1] - P[0] * B[1]) / math.hypot(B[0] - P[0], B[1] - P[1])


def strain_change(path: float, path0: float, L_w: float) -> float:
    """Delta eps = (path - path0) / L_w, Eqs. (4a)/(5a)/(6)."""
    return (path - path0) / L_w


# --------------------------------------------------------------------------------------------
# Eqs. (1)-(2): dynamics and friction
# --------------------------------------------------------------------------------------------
def gravity_moment(m: float, g: float, d_CM: float, theta: float) -> float:
    """Gravity's moment about the joint, the last term of Eq. (1b): -m g d_CM cos(theta)."""
    return -m * g * d_CM * math.cos(theta)


def bias_spring_load(K: float, preload: float, external: float, x: float) -> float:
    """The slider's load apart from the wire [N]: the bias spring and a constant force pull back."""
    return -(preload + K * x) - external


def sliding_friction(v: float, dynamic: float, viscous: float) -> float:
    """M_Fr of Eq. (2) while sliding: sign(v) (M_DF + C_DF |v|) (0 at v = 0)."""
    if v == 0.0:
        return 0.0
    return math.copysign(dynamic + viscous * abs(v), v)


def acceleration(load: float, v: float, stuck: bool, inertia: float, dynamic: float, viscous: float) -> float:
    """q'' of Eq. (1a): (M_E - M_Fr) / I; 0 while held by static friction (M_Fr = M_E)."""
    if stuck:
        return 0.0
    return (load - sliding_friction(v, dynamic, viscous)) / inertia
