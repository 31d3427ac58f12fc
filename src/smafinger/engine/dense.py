"""Output samples between sub-step starts (the averaged PWM's long steps).

With the exact PWM every output sample is a sub-step start, where the state and the algebraic
quantities are known. With long steps (``pwm="averaged"``) a sample can fall inside a step:
its continuous signals (the state, and xi, stress, force, arm, spring and load) are
interpolated linearly between the sub-step's start and end, and its discrete ones (duty,
drive, enable and heating flags, stuck, target, segment) are those held over the sub-step.
Linear interpolation adds an error of h^2/8 max|y''| at most, below the step's own error
at first order.
"""

from ..jit import njit
from ..model.records import Aux, State, WireAux, WireState
from .rhs import ZERO_WIRE_AUX
from .tuples import filled, set_item


@njit(cache=True, forceinline=True)
def zero_aux(wires):
    """An :class:`~smafinger.model.records.Aux` of zeros for ``wires`` (a typed placeholder)."""
    return Aux(0.0, filled(wires, ZERO_WIRE_AUX))


@njit(cache=True, forceinline=True)
def _mix(a, b, w):
    return a + w * (b - a)


@njit(cache=True)
def _wire_state(a, b, w):
    return WireState(_mix(a.T_C, b.T_C, w), _mix(a.sigma_Pa, b.sigma_Pa, w), _mix(a.electrical_J, b.electrical_J, w),
                     _mix(a.heat_J, b.heat_J, w), _mix(a.T_case_C, b.T_case_C, w),
                     _mix(a.xi_integrated, b.xi_integrated, w))


@njit(cache=True)
def _wire_aux(a, b, w):
    return WireAux(_mix(a.xi, b.xi, w), _mix(a.sigma_Pa, b.sigma_Pa, w), _mix(a.force_N, b.force_N, w),
                   _mix(a.spring_m, b.spring_m, w), _mix(a.arm_m, b.arm_m, w), _mix(a.dT_C_s, b.dT_C_s, w),
                   a.rates_per_v)


@njit(cache=True, forceinline=True)
def interpolated(y0, aux0, y1, aux1, w):
    """(state, aux) a fraction ``w`` in [0, 1] of the way from (y0, aux0) to (y1, aux1)."""
    ws = y0.wires
    was = aux0.wires
    for i in range(len(ws)):
        ws = set_item(ws, i, _wire_state(y0.wires[i], y1.wires[i], w))
        was = set_item(was, i, _wire_aux(aux0.wires[i], aux1.wires[i], w))
    y = State(_mix(y0.q, y1.q, w), _mix(y0.v, y1.v, w), _mix(y0.error_integral, y1.error_integral, w), ws)
    return y, Aux(_mix(aux0.load, aux1.load, w), was)
