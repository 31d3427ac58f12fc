"""Drive the hysteresis operator over a sampled history, the way the engine drives it.

Between samples the input (T, sigma) is taken as moving monotonically (linearly). At every
sample k the direction for the next interval is taken from the sign of the change
(:func:`~smafinger.model.hysteresis.drive_direction` with dT = T[k+1] - T[k] and
dsigma = sigma[k+1] - sigma[k]), ``update_memory`` commits the events at (T[k], sigma[k]),
and xi[k] is evaluated with the updated record (as the engine samples its outputs).
``xi_step_end[k]`` is the value at sample k from the previous interval's record, before the
update: it shows what the engine's right-hand side sees inside a sub-step.
"""

import math
from typing import NamedTuple

import numpy as np

from ..jit import njit
from .hysteresis import (
    AUTHORS2020, DEADBAND, DEFAULT_CAPACITY, DEFAULT_RULE, KineticsMaterial, drive_direction, initial_record,
    new_stack, rule_code, update_memory, xi_on_branch,
)


class HistoryResult(NamedTuple):
    """Output of :func:`xi_history` (arrays of the history's length, counts at the end)."""

    xi: np.ndarray
    xi_step_end: np.ndarray
    depth: np.ndarray
    clamps: int
    merges: int


@njit(cache=True)
def _drive(rule, T, sigma, m, xi_init, reversal_C, stack, xi, xi_end, depth_out):
    rec, depth = initial_record(rule, xi_init, T[0], reversal_C)
    n = T.shape[0]
    direction = 0
    for k in range(n):
        xi_end[k] = xi_on_branch(rec, T[k], sigma[k], m)[0]
        if k + 1 < n:
            direction = drive_direction(rec, T[k + 1] - T[k], sigma[k + 1] - sigma[k], m)
        rec, depth = update_memory(rec, stack, depth, T[k], sigma[k], direction, m)
        xi[k] = xi_on_branch(rec, T[k], sigma[k], m)[0]
        depth_out[k] = depth
    return rec.clamps, rec.merges


def xi_history(T, sigma, material, xi_init=1.0, rule=DEFAULT_RULE, reversal_C=None,
               capacity=DEFAULT_CAPACITY):
    """xi along a sampled history of temperature (degC) and stress (Pa).

    Parameters
    ----------
    T, sigma : array_like
        Samples of the same length (at least 1), finite.
    material : KineticsMaterial
    xi_init : float
        Martensite fraction before the first motion, in [0, 1].
    rule : {"memory", "authors2020", "deadband"}
    reversal_C : float, optional
        Dead-band threshold (degC, > 0); default 0.5 for ``"deadband"``, 0 otherwise.
    capacity : int
        Stack rows (memory rule).

    Returns
    -------
    HistoryResult
    """
    code = rule_code(rule)
    if not isinstance(material, KineticsMaterial):  # a parameter set reached numba's typing (found by an API fuzz)
        raise TypeError(f"material = {type(material).__name__}: give a KineticsMaterial "
                        "(kinetics_material(...), or material_from_parameters(a parameter set))")
    T = np.ascontiguousarray(T, dtype=np.float64)
    sigma = np.ascontiguousarray(sigma, dtype=np.float64)
    if T.ndim != 1 or T.shape != sigma.shape or T.size == 0:
        raise ValueError(f"T and sigma must be 1-D of one length >= 1, got shapes {T.shape}"
                         f" and {sigma.shape}")
    for name, a in (("T", T), ("sigma", sigma)):
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} has a non-finite sample at index "
                             f"{int(np.flatnonzero(~np.isfinite(a))[0])}")
    if not 0.0 <= xi_init <= 1.0:
        raise ValueError(f"xi_init = {xi_init} is not in [0, 1]")
    if reversal_C is None:
        reversal_C = 0.5 if code == DEADBAND else 0.0
    if code == DEADBAND and not (reversal_C > 0.0 and math.isfinite(reversal_C)):  # inf never transformed
        raise ValueError(f"reversal_C = {reversal_C} must be a finite number > 0 for the deadband rule")
    if code == AUTHORS2020 and reversal_C != 0.0:
        raise ValueError(f"reversal_C = {reversal_C} must be 0 for the authors2020 rule")
    stack = new_stack(capacity)
    xi = np.empty_like(T)
    xi_end = np.empty_like(T)
    depth = np.empty(T.shape, dtype=np.int64)
    clamps, merges = _drive(code, T, sigma, material, float(xi_init), float(reversal_C), stack,
                            xi, xi_end, depth)
    return HistoryResult(xi, xi_end, depth, int(clamps), int(merges))
