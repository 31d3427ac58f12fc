"""Eqs. (3)-(6): tendon path, total-strain variation and moment arm.

Frame O-XY at the MCP joint centre; theta from the X axis, positive = extension.
Point B on the phalanx (Eq. 3): B = r (cos(theta + alpha0), sin(theta + alpha0)).
Fixed points (MODEL-NOTES): upper C_U = (-a5, +a1), D_U = (+a2, +a1); lower
C_L = (-a4, -a1), D_L = (+a2, -a1).

Configuration switch: while Y_B(upper) >= Y_C(upper) (finger up or level) the upper tendon
runs straight C_U -> B_U (Configuration I, Eq. 4) and the lower wraps over D_L
(Configuration II, Eq. 5); otherwise the upper wraps over D_U and the lower runs straight.
The path length includes the fixed segment |C D| when wrapped, so that it is continuous at
the switch; Eq. (6): Delta eps = (path(theta) - path(theta0)) / L_w.
The moment arm is b = |X_B Y_P - X_P Y_B| / |P B| with P the point the tendon leaves from
(Eqs. 4b, 5b); it equals |d path / d theta|.
"""

import math

from numba import njit


@njit(cache=True)
def upper_is_straight(theta, r, alpha0_upper, a1):
    """Configuration I for the upper tendon: Y of B_U >= Y of C_U."""
    return r * math.sin(theta + alpha0_upper) >= a1


@njit(cache=True)
def tendon(theta, r, alpha0, xc, yc, xd, yd, wrapped):
    """Path length [m], d(path)/d(theta) [m/rad] and moment arm b [m] of one tendon.

    Eqs. (3), (4a)/(5a) without the reference subtraction, (4b)/(5b).
    """
    a = theta + alpha0
    xb = r * math.cos(a)
    yb = r * math.sin(a)
    if wrapped:
        xp = xd
        yp = yd
        fixed = math.sqrt((xd - xc) ** 2 + (yd - yc) ** 2)
    else:
        xp = xc
        yp = yc
        fixed = 0.0
    dpb = math.sqrt((xb - xp) ** 2 + (yb - yp) ** 2)
    # d|PB|/dtheta with dB/dtheta = (-yb, xb)
    dpath = (xp * yb - yp * xb) / dpb
    arm = abs(xb * yp - xp * yb) / dpb
    return fixed + dpb, dpath, arm


@njit(cache=True)
def both_tendons(theta, r, a0u, a0l, a1, a2, a4, a5):
    """(path_U, dpath_U, arm_U, path_L, dpath_L, arm_L) at angle theta."""
    straight_u = upper_is_straight(theta, r, a0u, a1)
    pu, du, bu = tendon(theta, r, a0u, -a5, a1, a2, a1, not straight_u)
    pl, dl, bl = tendon(theta, r, a0l, -a4, -a1, a2, -a1, straight_u)
    return pu, du, bu, pl, dl, bl
