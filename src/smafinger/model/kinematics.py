"""Eqs. (3)-(6): a wire's path to the mechanism, its change with q, and its moment arm.

Joint (:class:`TendonRoute`). Frame O-XY at the MCP joint centre; theta from the X axis,
positive = extension. Point B on the phalanx (Eq. 3): B = r (cos(theta + alpha0),
sin(theta + alpha0)), computed as B0 = r (cos alpha0, sin alpha0) turned by theta. Fixed
points (MODEL-NOTES): upper C_U = (-a5, +a1), D_U = (+a2, +a1); lower C_L = (-a4, -a1),
D_L = (+a2, -a1). Configuration switch: while Y_B(upper) >= Y_C(upper)
(finger up or level) the upper tendon runs straight C_U -> B_U (Configuration I, Eq. 4) and
the lower wraps over D_L (Configuration II, Eq. 5); otherwise the upper wraps over D_U and the
lower runs straight. The path length includes the fixed segment |C D| when wrapped, so that it
is continuous at the switch; Eq. (6): Delta eps = (path(theta) - path(theta0)) / L_w. The
moment arm is b = |X_B Y_P - X_P Y_B| / |P B| with P the point the tendon leaves from
(Eqs. 4b, 5b); it equals |d path / d theta|.

Linear actuator (:class:`DirectPull`): the wire pulls the slider along its own axis, so its
path shortens by exactly the slider's displacement: d path / d x = -1.

:func:`route` gives (path, d path / d q, arm) for either; a wire's generalized force is
``-F d path / d q`` (virtual work), which is F b for the upper tendon and -F b for the lower.
"""

import math
from typing import NamedTuple

from numba import types
from numba.extending import overload

from ..jit import njit


class TendonRoute(NamedTuple):
    """One tendon of the joint (Eqs. 3-5); the switch is the upper B passing C_U's height.

    B and the switch's point are held at theta = 0 and turned by theta (Eq. 3 as a rotation:
    r (cos(theta + alpha0), sin(theta + alpha0)) is B0 = r (cos alpha0, sin alpha0) turned by
    theta), so that every wire's geometry takes the one cosine and sine of theta.
    """

    B0_x_m: float  #: B at theta = 0: r cos(alpha0)
    B0_y_m: float  #: r sin(alpha0)
    C_x_m: float
    C_y_m: float
    D_x_m: float
    D_y_m: float
    switch_x_m: float  #: the configuration switch's point (the upper B) at theta = 0
    switch_y0_m: float
    switch_y_m: float  #: "up" while that point, turned by theta, is at this height or above
    wrapped_when_up: bool  #: the lower tendon wraps over D while the finger is up, the upper while down


class WireGeometry(NamedTuple):
    """Where a wire meets the mechanism at coordinate q (what :func:`route` returns)."""

    path_m: float  #: path length (Eq. 6 takes its change)
    dpath_dq: float  #: d path / d q (m/rad or m/m)
    arm_m: float  #: moment arm b (Eqs. 4b, 5b); 1 for a slider


class DirectPull(NamedTuple):
    """A wire pulling a slider along its axis."""

    dpath_dq: float  #: -1: the path shortens as the slider moves in the pulling direction


@njit(cache=True, forceinline=True)
def tendon_at(xb, yb, xc, yc, xd, yd, wrapped):
    """:class:`WireGeometry` of one tendon with B = (xb, yb) (Eq. 3): path length [m],
    d(path)/d(theta) [m/rad], moment arm b [m]; Eqs. (4a)/(5a) without the reference
    subtraction, (4b)/(5b)."""
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
    return WireGeometry(fixed + dpb, dpath, arm)


@njit(cache=True, forceinline=True)
def tendon_route(rt, theta, cos_theta, sin_theta):
    """(path, dpath/dtheta, arm) of a joint tendon, with its Configuration I/II switch;
    ``cos_theta``, ``sin_theta``: those of theta [rad] (B = B0 turned by theta, Eq. 3)."""
    xb = rt.B0_x_m * cos_theta - rt.B0_y_m * sin_theta
    yb = rt.B0_x_m * sin_theta + rt.B0_y_m * cos_theta
    up = rt.switch_x_m * sin_theta + rt.switch_y0_m * cos_theta >= rt.switch_y_m
    wrapped = up if rt.wrapped_when_up else not up
    return tendon_at(xb, yb, rt.C_x_m, rt.C_y_m, rt.D_x_m, rt.D_y_m, wrapped)


@njit(cache=True, forceinline=True)
def direct_pull(rt, x, cos_x, sin_x):
    """(path, dpath/dx, arm) of a wire pulling a slider: path = -x from the start (the cosine
    and sine are not used: every route takes them)."""
    return WireGeometry(rt.dpath_dq * x, rt.dpath_dq, 1.0)


def route(rt, q, cos_q, sin_q):
    """The :class:`WireGeometry` of a wire at coordinate q (``cos_q``, ``sin_q``: its cosine
    and sine, computed once for all the wires); dispatched on the route's type."""
    return _ROUTES[type(rt)](rt, q, cos_q, sin_q)


#: each route record and its geometry function
_ROUTES = {TendonRoute: tendon_route, DirectPull: direct_pull}


@overload(route)
def _route(rt, q, cos_q, sin_q):
    if isinstance(rt, types.BaseNamedTuple) and rt.instance_class in _ROUTES:
        f = _ROUTES[rt.instance_class]
        return lambda rt, q, cos_q, sin_q: f(rt, q, cos_q, sin_q)
    return None


@njit(cache=True)
def wire_route(rt, q):
    """:func:`route` at q, also callable from Python (compiled once per route type)."""
    return route(rt, q, math.cos(q), math.sin(q))
