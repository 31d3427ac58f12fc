"""Eqs. (9)-(10) as the authors' Simulink model runs them: one call per model evaluation.

Their martensite-fraction functions (``Code/SMA1_Martensite_Fraction.m`` and
``SMA2_Martensite_Fraction.m`` in gabrielegilardi/FingerControl, commit 8910187; lines below are
SMA1's) keep three globals per wire,
``Es`` (the heating branch's start, Eq. 9b's xi_M0), ``Ef`` (the cooling branch's start,
Eq. 10b's xi_A0) and ``Esave`` (the last output), and change them at every call:

- the branch is the sign of the call's own dT/dt (l. 14, 28, 47, 66), wired from the heat
  model's integrator input at the same evaluation (``Finger_Full_Model.mdl``, the bus into
  "Phase Transformation Model SMA 1", SID 288);
- heating: E = Es (T < Ua), Es (1 + kA) / 2 (Ua <= T <= La), 0 (T > La) (l. 30-36); then Ef is
  re-solved so that the cooling branch passes through E: (2E - (1 + kM)) / (1 - kM) below Lm,
  E above (l. 38-42);
- cooling: E = Ef (T > Lm), Ef + (1 - Ef)(1 + kM) / 2 (Um <= T <= Lm), 1 (T < Um) (l. 49-55);
  then Es is re-solved so that the heating branch passes through E: 2E / (1 + kA) above Ua,
  E below (l. 57-61);
- dT/dt = 0: E = Esave (l. 66-68); Esave = E after every call (l. 70).

kA = cos(a_A (T - A_s) + b_A sigma) and kM = cos(a_M (T - M_f) + b_M sigma) (l. 24-25) are the
raw cosines, not the major curves clamped at their ends: above La the re-solved Es is
2E / (1 + kA) with 1 + kA small (the branch keeps E at the current point), where the clamped
curve would give 0 and lose the point.

A call's E depends only on the global it does not change (Es when heating, Ef when cooling),
so the iterations of Simulink's algebraic-loop solver (stress and E, through the ``IC``
blocks SIDs 460 and 464) all see the same E(T, sigma): the loop's solution is the engine's
:func:`~smafinger.model.wire.algebraic_stress` on that branch, and only the global written by
the solver's last call, taken here at the solution, depends on the iterations.

The globals live in the wire's :class:`~smafinger.model.hysteresis.BranchRecord` under the
rule code :data:`AUTHORS_CALLS` (:func:`globals_of`), the fields that the other rules use for
their parent branch; ``direction``, ``x0`` and ``slope`` hold the last call's branch, so that
``xi_on_branch`` gives the last call's E.
"""

import math

from ..jit import njit
from .hysteresis import AUTHORS_CALLS, BranchRecord
from .kinetics import COOLING, HEATING, branch_start
RAW = False


@njit(cache=True, forceinline=True)
def globals_of(rec):
    """(Es, Ef, Esave): the authors' three globals of one wire, kept in its branch record."""
    return rec.parent_x0, rec.parent_slope, rec.target_xi


@njit(cache=True, forceinline=True)
def _record(phase, Es, Ef, Esave):
    """The record of a call with branch ``phase`` (+1, -1, 0) and the globals (Es, Ef, Esave):
    heating xi = Es g_A, cooling xi = Ef + (1 - Ef) g_M (Eqs. 9b, 10b), hold xi = Esave."""
    if phase > 0:
        x0, slope = 0.0, Es
    elif phase < 0:
        x0, slope = Ef, 1.0 - Ef
    else:
        x0, slope = Esave, 0.0
    return BranchRecord(AUTHORS_CALLS, phase, x0, 0.0, slope, 0.0, 0.0, math.inf, Esave, Es, 0.0, Ef,
                        0.0, 0.0, 0, 0)


@njit(cache=True)
def initial_calls_record(xi_init):
    """Before the first call (``Initialization.m``): Es = Esave = xi_init (their 1), Ef = 0."""
    return _record(0, xi_init, 0.0, xi_init)


@njit(cache=True, forceinline=True)
def call_record(rec, dT_dt):
    """The record a call evaluates with: its branch from the sign of its dT/dt, the globals kept."""
    Es, Ef, Esave = globals_of(rec)
    phase = 1 if dT_dt > 0.0 else (-1 if dT_dt < 0.0 else 0)
    return _record(phase, Es, Ef, Esave)


@njit(cache=True)
def committed_call(rec, T, sigma, E, m):
    """The globals after a call on ``rec``'s branch that returned E at (T, sigma) (Eqs. 9b, 10b
    re-solved for their start values, with the raw cosines; see the module docstring)."""
    Es, Ef, _ = globals_of(rec)
    if rec.direction > 0:
        Lm = m.M_S0_C + sigma / m.c_M_Pa_per_C
        Ef = E
        if T < Lm:
            kM = math.cos(math.pi / (m.M_S0_C - m.M_F0_C) * (T - m.M_F0_C - sigma / m.c_M_Pa_per_C))
            if kM != 1.0:
                Ef = (2.0 * E - (1.0 + kM)) / (1.0 - kM)
    elif rec.direction < 0:
        Ua = m.A_S0_C + sigma / m.c_A_Pa_per_C
        Es = E
        if T > Ua:
            kA = math.cos(math.pi / (m.A_F0_C - m.A_S0_C) * (T - m.A_S0_C - sigma / m.c_A_Pa_per_C))
            if kA != -1.0:
                Es = 2.0 * E / (kA + 1.0)
    return _record(rec.direction, Es, Ef, E)
