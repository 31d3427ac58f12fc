"""Sliding-mode control with a boundary layer, duty out through the paper's phase selection.

Sliding surface (integral sliding, so that a hold needs no steady error)::

    s = de/dt + lambda e + lambda_I integral(e) dt,   e = q_F - q,  de/dt = -q'       (SM1)

and the control law, the switching term smoothed inside a boundary layer of half-width phi
(Slotine and Li, Applied Nonlinear Control, Prentice Hall 1991, Sec. 7.2)::

    DC% = K sat(s / phi),   sat(x) = min(max(x, -1), 1)                              (SM2)

K is the switching gain in DC% (100: the full supply at |s| >= phi). Sliding-mode and
variable-structure control of SMA actuators: Grant and Hayward, "Variable structure control of
shape memory alloy actuators", IEEE Control Systems 17(3):80-88, 1997; Elahinia and
Ashrafiuon, "Nonlinear control of a shape memory alloy actuated manipulator", ASME J. Vib.
Acoust. 124(4):566-575, 2002 (the paper's refs. 12 and 25 are of this family). The integral is
the plant state's error integral (reset per segment like the PID's, frozen by anti-windup
while the output is at +-K and the error pushes it further: :func:`.chain.law_limit`).
"""

from typing import NamedTuple

from ..jit import njit



class SlidingMode(NamedTuple):
    """Sliding-mode parameters (q in rad for the joint, m for a slider)."""

    lam: float  #: lambda [1/s]: the surface's error weight (its time constant 1/lambda)
    lam_I: float  #: lambda_I [1/s^2]: integral weight
    phi: float  #: boundary-layer half-width [q/s]
    K: float  #: switching gain [%]


@njit(cache=True, forceinline=True)
def surface(ctrl, e, de, integral):
    """s of Eq. (SM1) [q/s]."""
    return de + ctrl.lam * e + ctrl.lam_I * integral


@njit(cache=True, forceinline=True)
def switching(ctrl, s):
    """DC% of Eq. (SM2) (signed; the phase selection clamps it per wire)."""
    return ctrl.K * min(max(s / ctrl.phi, -1.0), 1.0)


@njit(cache=True, forceinline=True)
def sliding_output(ctrl, e, de, integral):
    """DC% of Eqs. (SM1)-(SM2)."""
    return switching(ctrl, surface(ctrl, e, de, integral))
